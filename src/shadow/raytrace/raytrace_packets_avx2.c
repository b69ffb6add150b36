/* The AVX2 instance of the raytrace packet tracer (raytrace_impl.h). */
#include "raytrace_impl.h"
