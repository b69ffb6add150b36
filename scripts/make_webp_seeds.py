#!/usr/bin/env python3
"""The seed corpus of the WebP fuzzer (tests/fuzz/corpus/webp/): small valid WebP files as libwebp's encoder
writes them: lossless RGBA, lossless RGB, lossy RGB, lossy with an alpha channel, of a few sizes. Each must
decode (test_fuzz_inputs replays them). Encoded through Debian's libwebp (ctypes on libwebp.so), so that no
Python package is needed.

    python3 scripts/make_webp_seeds.py [OUT_DIR]    (default tests/fuzz/corpus/webp)
"""
import ctypes
import ctypes.util
import os
import sys


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "tests", "fuzz", "corpus", "webp")
    os.makedirs(out, exist_ok=True)
    lib = ctypes.CDLL(ctypes.util.find_library("webp") or "libwebp.so.7")
    pp = ctypes.POINTER(ctypes.POINTER(ctypes.c_uint8))
    for name in ("WebPEncodeRGBA", "WebPEncodeRGB"):
        f = getattr(lib, name)
        f.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_float, pp]
        f.restype = ctypes.c_size_t
    for name in ("WebPEncodeLosslessRGBA", "WebPEncodeLosslessRGB"):
        f = getattr(lib, name)
        f.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_int, ctypes.c_int, pp]
        f.restype = ctypes.c_size_t
    lib.WebPFree.argtypes = [ctypes.c_void_p]

    def image(w, h, ch):
        return bytes(((x * 37 + y * 11 + c * 71) ^ (x * y)) & 255 for y in range(h) for x in range(w) for c in range(ch))

    for (w, h) in ((1, 1), (7, 5), (33, 17)):
        for kind in ("lossless_rgba", "lossless_rgb", "lossy_rgb", "lossy_rgba"):
            ch = 4 if kind.endswith("rgba") else 3
            px = image(w, h, ch)
            buf = ctypes.POINTER(ctypes.c_uint8)()
            if kind.startswith("lossless"):
                f = lib.WebPEncodeLosslessRGBA if ch == 4 else lib.WebPEncodeLosslessRGB
                n = f(px, w, h, w * ch, ctypes.byref(buf))
            else:
                f = lib.WebPEncodeRGBA if ch == 4 else lib.WebPEncodeRGB
                n = f(px, w, h, w * ch, 75.0, ctypes.byref(buf))
            if not n:
                sys.exit("make_webp_seeds: libwebp could not encode %s %dx%d" % (kind, w, h))
            data = ctypes.string_at(buf, n)
            lib.WebPFree(buf)
            with open(os.path.join(out, "%s_%dx%d.webp" % (kind, w, h)), "wb") as fh:
                fh.write(data)


if __name__ == "__main__":
    main()
