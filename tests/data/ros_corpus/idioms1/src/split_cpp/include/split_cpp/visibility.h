#ifndef SPLIT_CPP_VISIBILITY_H
#define SPLIT_CPP_VISIBILITY_H
#define SPLIT_CPP_PUBLIC __attribute__((visibility("default")))
#endif
