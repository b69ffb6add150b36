/* The AVX-512 instance of the grid weights of S (receiver_weights_impl.h). */
#include "receiver_weights_impl.h"
