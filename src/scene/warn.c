#include "microshadow.h"
#include "scene_internal.h"
#include <stdarg.h>
#include <stdio.h>

static ms_warning_fn g_warn;
static void *g_warn_user;
static int g_verbose;

/* The material warnings of the scene being loaded (ms_material_warnings_begin/end), per thread. */
static _Thread_local struct {
    int active;
    size_t count;
    char first[1024];
} g_mat;

void ms_set_warning_handler(ms_warning_fn fn, void *user)
{
    g_warn = fn;
    g_warn_user = user;
}

void ms_set_warning_verbose(int verbose) { g_verbose = verbose != 0; }

static void emit(char *msg)
{
    ms_one_line(msg);
    if (g_warn) g_warn(g_warn_user, msg);
    else fprintf(stderr, "microshadow: warning: %s\n", msg);
}

void ms_warn(const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    emit(msg);
}

void ms_warn_material(const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (!g_mat.active || g_verbose) { emit(msg); return; }
    if (g_mat.count++ == 0) snprintf(g_mat.first, sizeof g_mat.first, "%s", msg);
}

void ms_material_warnings_begin(void)
{
    g_mat.active = 1;
    g_mat.count = 0;
    g_mat.first[0] = 0;
}

void ms_material_warnings_end(int report)
{
    if (report && g_mat.count == 1) emit(g_mat.first);
    else if (report && g_mat.count > 1) {
        char msg[1400];
        snprintf(msg, sizeof msg, "%zu material files, textures or glTF features could not be used; those materials keep "
                 "their factors or the default grey, --verbose lists each (first: %.1200s)", g_mat.count, g_mat.first);
        emit(msg);
    }
    g_mat.active = 0;
    g_mat.count = 0;
}

void ms_one_line(char *err)
{
    for (unsigned char *p = (unsigned char *)err; *p; p++)
        if (*p < 0x20 || *p == 0x7f) *p = '?';
}
