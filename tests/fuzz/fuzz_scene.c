/* libFuzzer harness for scene JSON (parsing, keys, values, validation, and loading the meshes it names). */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_scene(ms_fuzz_scene_dir(), data, size); return 0; }
