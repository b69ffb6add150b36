/* Test hooks: measuring switches (a part of a method turned off, to measure what it buys) and deliberate faults
 * (a part made wrong, to show a test depends on it) exist only in microshadow_test, the copy of the library the
 * tests and benchmarks link, compiled with MS_TEST_HOOKS (CMakeLists.txt). The library users get has none: there,
 * every hook reads as 0 and its branch folds away. A source of the library that includes this header must be
 * listed in CMakeLists.txt's MS_HOOKED_SOURCES, which compiles it in both forms (and defines MS_HOOKABLE; a
 * sanitized build, the test suite's own, only the hooked one). */
#ifndef MS_TEST_HOOKS_H
#define MS_TEST_HOOKS_H

#if !defined(MS_HOOKABLE) && !defined(MS_TEST_HOOKS)
#error "a library source that reads test hooks belongs in MS_HOOKED_SOURCES (CMakeLists.txt)"
#endif

/* MS_HOOK(x): the value of a hook expression x in the tests' copy, 0 in the library users get (x is then not
 * compiled, so the hooks' variables need not exist there). */
#ifdef MS_TEST_HOOKS
#define MS_HOOK(x) (x)
#else
#define MS_HOOK(x) 0
#endif

#endif
