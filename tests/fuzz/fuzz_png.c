/* libFuzzer harness for PNG textures, light and material (src/image/png_read.c, src/scene/texture.c; body: ms_fuzz_png in fuzz_entry.h). */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_png(data, size); return 0; }
