/* The one translation unit that compiles the vendored cgltf (third_party/cgltf, v1.15). */
#define CGLTF_IMPLEMENTATION
#include "cgltf.h"
