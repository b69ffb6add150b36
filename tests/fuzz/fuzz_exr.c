/* libFuzzer harness for EXR light textures (src/image/exr_read.c: OpenEXRCore from memory). */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_exr(data, size); return 0; }
