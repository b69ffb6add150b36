/* libFuzzer harness for MTL files (src/scene/mtl.c; body: ms_fuzz_mtl in fuzz_entry.h). */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_mtl(data, size); return 0; }
