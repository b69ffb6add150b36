/* The portable instance of method mft's block tracers (mft_impl.h, mft_group_impl.h). */
#include "mft_impl.h"
#include "mft_group_impl.h"
