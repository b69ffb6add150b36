/* libFuzzer harness for material textures (src/scene/texture.c): JPEG through TurboJPEG, which must report
 * every error and never exit or abort; PNG and KTX2 inputs the fuzzer reaches go to their decoders. */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_jpeg(data, size); return 0; }
