#include "microshadow.h"
#include "scene_internal.h"
#include <stdarg.h>
#include <stdio.h>

static ms_warning_fn g_warn;
static void *g_warn_user;

void ms_set_warning_handler(ms_warning_fn fn, void *user)
{
    g_warn = fn;
    g_warn_user = user;
}

void ms_warn(const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ms_one_line(msg);
    if (g_warn) g_warn(g_warn_user, msg);
    else fprintf(stderr, "microshadow: warning: %s\n", msg);
}

void ms_one_line(char *err)
{
    for (unsigned char *p = (unsigned char *)err; *p; p++)
        if (*p < 0x20 || *p == 0x7f) *p = '?';
}
