#!/usr/bin/env python3
"""Crytek's Sponza as one glTF binary, from the per-part OBJ export in ../shared/scenes/crytek-sponza-partial.

Khronos' glTF Sponza cannot be fetched here (its 9 MB Sponza.bin is absent from every stored copy), so the
lightmap figures of docs/baking.md take the same model's OBJ parts: merged into one OBJ (each part's indices
offset, its materials kept by name with a plain grey, the textures being absent from the source; the duplicate
sponza_vase_plant.obj left out), converted by assimp's exporter (Debian's assimp-utils), and its materials'
KHR_materials_pbrSpecularGlossiness and FB_ngon_encoding (which assimp always writes) removed so that the
metallic-roughness factors are what a viewer reads.

Usage: scripts/sponza_gltf.py SOURCE_DIR OUT.glb"""
import json
import os
import struct
import subprocess
import sys
import tempfile


def merge(src, obj, mtl):
    parts = [p for p in sorted(os.listdir(src)) if p.endswith('.obj') and p != 'sponza_vase_plant.obj']
    base = [0, 0, 0]   # vertices, texture coordinates, normals before the part
    mats = []
    with open(obj, 'w') as out:
        out.write('mtllib %s\n' % os.path.basename(mtl))
        for p in parts:
            count = [0, 0, 0]
            out.write('o %s\n' % p[:-4])
            for line in open(os.path.join(src, p)):
                w = line.split()
                if not w:
                    continue
                if w[0] in ('v', 'vt', 'vn'):
                    count[('v', 'vt', 'vn').index(w[0])] += 1
                    out.write(line)
                elif w[0] == 'usemtl':
                    m = w[1].replace(':', '_')
                    if m not in mats:
                        mats.append(m)
                    out.write('usemtl %s\n' % m)
                elif w[0] == 'f':
                    corners = []
                    for c in w[1:]:
                        ix = c.split('/')
                        corners.append('/'.join('' if i == '' else str(int(i) + base[k] if int(i) > 0 else int(i))
                                                for k, i in enumerate(ix)))
                    out.write('f %s\n' % ' '.join(corners))
            base = [b + c for b, c in zip(base, count)]
    with open(mtl, 'w') as out:
        for m in mats:
            out.write('newmtl %s\nKd 0.7 0.7 0.7\nillum 1\n' % m)
    return len(parts), base[0], len(mats)


def strip_extensions(path):
    data = open(path, 'rb').read()
    n = struct.unpack('<I', data[12:16])[0]
    doc = json.loads(data[20:20 + n])
    rest = data[20 + n:]
    drop = {'KHR_materials_pbrSpecularGlossiness', 'FB_ngon_encoding'}
    for m in doc.get('materials', []):
        for e in drop:
            m.get('extensions', {}).pop(e, None)
        if 'extensions' in m and not m['extensions']:
            del m['extensions']
    for mesh in doc.get('meshes', []):
        for prim in mesh.get('primitives', []):
            for e in drop:
                prim.get('extensions', {}).pop(e, None)
            if 'extensions' in prim and not prim['extensions']:
                del prim['extensions']
    for key in ('extensionsUsed', 'extensionsRequired'):
        if key in doc:
            doc[key] = [e for e in doc[key] if e not in drop]
            if not doc[key]:
                del doc[key]
    js = json.dumps(doc, separators=(',', ':')).encode()
    js += b' ' * (-len(js) % 4)
    out = struct.pack('<I4s', len(js), b'JSON') + js + rest
    with open(path, 'wb') as f:
        f.write(struct.pack('<4sII', b'glTF', 2, 12 + len(out)) + out)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[-1])
    src, glb = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        obj, mtl = os.path.join(tmp, 'sponza.obj'), os.path.join(tmp, 'sponza.mtl')
        parts, vertices, mats = merge(src, obj, mtl)
        subprocess.run(['assimp', 'export', obj, glb, '-fglb2'], check=True, stdout=subprocess.DEVNULL)
    strip_extensions(glb)
    print('%s: %d parts, %d vertices, %d materials' % (glb, parts, vertices, mats))


if __name__ == '__main__':
    main()
