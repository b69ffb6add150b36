#!/usr/bin/env python3
"""The seed corpus of the KTX2 fuzzer (tests/fuzz/corpus/ktx2/): small valid KTX2 files as real writers
make them (header, level index, a basic data format descriptor, key/value data, levels smallest last in
the index and smallest first in the file), uncompressed and Zstandard-supercompressed. Each must decode
(test_fuzz_inputs replays them). Zstandard through Debian's libzstd (ctypes on libzstd.so.1), so that no
Python package is needed.

    python3 scripts/make_ktx2_seeds.py [OUT_DIR]    (default tests/fuzz/corpus/ktx2)
"""
import ctypes
import ctypes.util
import os
import struct
import sys

ID = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])

# vkFormat -> (bytes per texel, channel ids of the DFD samples in byte order: 0 R, 1 G, 2 B, 15 A, sRGB?)
FORMATS = {9: (1, [0], False), 16: (2, [0, 1], False), 23: (3, [0, 1, 2], False), 29: (3, [0, 1, 2], True),
           36: (3, [2, 1, 0], True), 37: (4, [0, 1, 2, 15], False), 43: (4, [0, 1, 2, 15], True),
           50: (4, [2, 1, 0, 15], True)}


def zstd_compress(data, level):
    lib = ctypes.CDLL(ctypes.util.find_library("zstd") or "libzstd.so.1")
    lib.ZSTD_compressBound.restype = ctypes.c_size_t
    lib.ZSTD_compress.restype = ctypes.c_size_t
    lib.ZSTD_isError.restype = ctypes.c_uint
    cap = lib.ZSTD_compressBound(ctypes.c_size_t(len(data)))
    dst = ctypes.create_string_buffer(cap)
    n = lib.ZSTD_compress(dst, ctypes.c_size_t(cap), data, ctypes.c_size_t(len(data)), ctypes.c_int(level))
    if lib.ZSTD_isError(ctypes.c_size_t(n)):
        raise RuntimeError("ZSTD_compress failed")
    return dst.raw[:n]


def dfd(vk):
    """A basic data format descriptor block (Khronos Data Format 1.3) for one of FORMATS."""
    bpp, chans, srgb = FORMATS[vk]
    samples = b""
    for i, c in enumerate(chans):
        linear_alpha = 0x40 if (c == 15 and srgb) else 0   # KHR_DF_SAMPLE_DATATYPE_LINEAR: alpha is not sRGB
        samples += struct.pack("<HBB", 8 * i, 7, c | linear_alpha) + struct.pack("<III", 0, 0, 255)
    block_size = 24 + len(samples)
    block = struct.pack("<IHH", 0, 2, block_size)   # vendorId 0 (Khronos), descriptorType 0, version 2
    block += bytes([1, 1, 2 if srgb else 1, 0])     # model RGBSDA, primaries BT709, transfer, flags
    block += bytes([0, 0, 0, 0])                    # texel block 1x1x1x1
    block += bytes([bpp, 0, 0, 0, 0, 0, 0, 0])      # bytes per plane
    block += samples
    return struct.pack("<I", 4 + len(block)) + block


def ktx2(vk, w, h, levels, scheme, zlevel=3):
    """Levels of w x h, (w/2) x (h/2), ... of a fixed pattern; scheme 0 (none) or 2 (Zstandard)."""
    bpp = FORMATS[vk][0]
    datas = []
    for lv in range(levels):
        lw, lh = max(1, w >> lv), max(1, h >> lv)
        raw = bytes((17 * x + 31 * y + 7 * c + 50 * lv) & 255 for y in range(lh) for x in range(lw) for c in range(bpp))
        datas.append((raw, zstd_compress(raw, zlevel) if scheme == 2 else raw))
    d = dfd(vk)
    kv_pairs = [(b"KTXwriter", b"microshadow make_ktx2_seeds.py")]
    kvd = b""
    for k, v in kv_pairs:
        pair = k + b"\0" + v + b"\0"
        kvd += struct.pack("<I", len(pair)) + pair + b"\0" * (-len(pair) % 4)
    index_end = 80 + 24 * levels
    dfd_off = index_end
    kvd_off = dfd_off + len(d)
    pos = kvd_off + len(kvd)
    # Levels smallest first in the file, as the spec lays them out; aligned to lcm(bpp, 4) uncompressed.
    align = 1 if scheme == 2 else {1: 4, 2: 4, 3: 12, 4: 4}[bpp]
    body = b""
    entries = [None] * levels
    for lv in reversed(range(levels)):
        pad = -(pos + len(body)) % align
        body += b"\0" * pad
        raw, stored = datas[lv]
        entries[lv] = (pos + len(body), len(stored), len(raw))
        body += stored
    head = ID + struct.pack("<9I", vk, 1, w, h, 0, 0, 1, levels, scheme)
    head += struct.pack("<IIIIQQ", dfd_off, len(d), kvd_off, len(kvd), 0, 0)
    for e in entries:
        head += struct.pack("<QQQ", *e)
    return head + d + kvd + body


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "tests", "fuzz", "corpus", "ktx2")
    os.makedirs(out, exist_ok=True)
    seeds = {
        "rgba8_srgb_3x2.ktx2": ktx2(43, 3, 2, 1, 0),
        "r8_unorm_5x3_mips.ktx2": ktx2(9, 5, 3, 3, 0),
        "bgr8_srgb_4x3.ktx2": ktx2(36, 4, 3, 1, 0),
        "rgb8_unorm_zstd_7x5.ktx2": ktx2(23, 7, 5, 1, 2, zlevel=10),
        "rgba8_srgb_zstd_8x8_mips.ktx2": ktx2(43, 8, 8, 4, 2),
        "rg8_unorm_zstd_3x9.ktx2": ktx2(16, 3, 9, 1, 2, zlevel=19),
        "bgra8_srgb_zstd_2x2.ktx2": ktx2(50, 2, 2, 2, 2),
    }
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)
        print(f"{name}: {len(data)} bytes")


if __name__ == "__main__":
    main()
