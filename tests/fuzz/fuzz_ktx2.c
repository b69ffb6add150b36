/* libFuzzer harness for KTX2 material textures (src/scene/texture_ktx2.c): the header and level index,
 * every length and offset hostile, uncompressed and Zstandard-supercompressed levels (libzstd must report
 * every error and never write past the level's texels). Seeds: scripts/make_ktx2_seeds.py. */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_ktx2(data, size); return 0; }
