/* libFuzzer harness for one mesh format, MS_FUZZ_EXT (tests/fuzz/CMakeLists.txt builds one per format). */
#include "fuzz_entry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ms_fuzz_mesh(MS_FUZZ_EXT, data, size); return 0; }
