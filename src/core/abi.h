/* The check behind the API's checked entry points (microshadow/abi.h, "The ABI check"). */
#ifndef MS_CORE_ABI_H
#define MS_CORE_ABI_H
#include "microshadow.h"

/* MS_OK when every non-zero size in abi equals this library's, else MS_ERR_INVALID with one line naming fn, the
 * first struct that differs and both sizes in err (which may be NULL: the message is then dropped). */
ms_status ms_abi_check(const ms_abi *abi, const char *fn, char *err, size_t errlen);

#endif
