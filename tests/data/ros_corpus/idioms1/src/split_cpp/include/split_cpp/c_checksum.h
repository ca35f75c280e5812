/* A C header made includable from C++. */
#ifndef SPLIT_CPP_C_CHECKSUM_H
#define SPLIT_CPP_C_CHECKSUM_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

uint32_t frame_checksum(const uint8_t* data, uint32_t length);

#ifdef __cplusplus
}
#endif

#endif
