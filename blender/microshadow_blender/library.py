"""Finding microshadow's Python module and shared library from inside Blender.

Blender's Python is the system's (Debian's blender uses python3 and python3-numpy), so the module is the
repository's python/microshadow (ctypes over libmicroshadow.so). Looked for in order: the add-on's
preference "Library" (a path to libmicroshadow.so), a copy bundled beside the add-on (the zip
scripts/make_blender_addon.sh makes), the repository the add-on folder sits in (python/ and build/), and an
installed microshadow (cmake --install, pip install ./python).
"""
import importlib
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))

_module = None


class LibraryError(RuntimeError):
    pass


def _candidates(pref_library):
    if pref_library:
        yield bpy_abspath(pref_library)
    yield os.path.join(HERE, "lib", "libmicroshadow.so")
    for build in ("build", "build-release", "build-test"):
        yield os.path.join(REPO, build, "libmicroshadow.so")


def bpy_abspath(path):
    try:
        import bpy
        return bpy.path.abspath(path)
    except ImportError:  # outside Blender (the unit tests of light_units)
        return path


def module(pref_library=""):
    """The microshadow module, imported once (LibraryError with what was tried when it cannot be)."""
    global _module
    if _module is not None:
        return _module
    tried = []
    for lib in _candidates(pref_library):
        tried.append(lib)
        if os.path.isfile(lib):
            # the module's documented way to be given its library (python/microshadow/__init__.py)
            os.environ.setdefault("MICROSHADOW_LIBRARY", lib)
            break
    for path in (os.path.join(HERE, "lib"), os.path.join(REPO, "python")):
        if os.path.isfile(os.path.join(path, "microshadow", "__init__.py")) and path not in sys.path:
            sys.path.append(path)
    try:
        _module = importlib.import_module("microshadow")
    except ImportError as e:
        raise LibraryError("microshadow: the Python module or libmicroshadow.so was not found (%s; looked at %s): set "
                           "the add-on's Library preference" % (e, ", ".join(tried)))
    return _module
