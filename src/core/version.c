/* ms_version: the version of the library that is running (microshadow.h). */
#include "microshadow.h"

const char *ms_version(int *major, int *minor, int *patch)
{
    if (major) *major = MS_VERSION_MAJOR;
    if (minor) *minor = MS_VERSION_MINOR;
    if (patch) *patch = MS_VERSION_PATCH;
    return MS_VERSION_STRING;
}
