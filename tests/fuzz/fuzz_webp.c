/* libFuzzer harness for WebP material textures (src/scene/texture.c: libwebp's decoder behind the size check;
 * glTF's EXT_texture_webp). Seeds: scripts/make_webp_seeds.py. */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_webp(data, size); return 0; }
