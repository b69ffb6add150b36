/* The vendored LTC fit of GGX (third_party/ltc, Heitz et al. 2016) behind a C interface. C++ because the
 * file sizes its arrays with a `static const int`, which C does not take as a constant expression. */
#include "ltc_table.h"

namespace {
struct mat33 { double m[9]; };
#include "ltc.inc"
}

extern "C" {
int ms_ltc_table_size(void) { return size; }
const double *ms_ltc_table_minv(int index) { return tabMinv[index].m; }
float ms_ltc_table_magnitude(int index) { return tabMagnitude[index]; }
}
