#pragma once
#define COMP_DEMO_PUBLIC __attribute__((visibility("default")))
