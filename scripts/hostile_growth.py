#!/usr/bin/env python3
"""Writes the small hostile files whose loading once grew faster than their
size (docs/results.md, "Hostile scene files"; docs/limits.md, "Work that
grows with the input"):

    emitters N   N emitting rectangles in one XML scene
    copies N     an OBJ of N copies of one triangle, in an XML scene
    polygon N    an OBJ of one polygon of N vertices, in an XML scene
    nodes N      a glTF file whose N nodes place one one-triangle mesh

Usage: hostile_growth.py KIND N NAME  (writes NAME.xml, NAME.obj or
NAME.gltf in the current folder). Time one with
/usr/bin/time -f "%e s %M KB" trilux info NAME.xml >/dev/null
"""
import base64
import json
import math
import struct
import sys

SENSOR = ('<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,5" '
          'target="0,0,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" '
          'value="8"/><integer name="height" value="8"/></film><sampler type="independent">'
          '<integer name="sample_count" value="1"/></sampler></sensor>')
EMITTER = '<emitter type="area"><rgb name="radiance" value="1"/></emitter>'


def obj_scene(name):
    with open(name + '.xml', 'w') as f:
        f.write(f'<scene version="3.0.0">\n{SENSOR}\n<shape type="obj"><string name="filename" '
                f'value="{name}.obj"/>{EMITTER}</shape>\n</scene>\n')


def emitters(n, name):
    with open(name + '.xml', 'w') as f:
        f.write(f'<scene version="3.0.0">\n{SENSOR}\n')
        for i in range(n):
            f.write(f'<shape type="rectangle"><transform name="to_world"><translate '
                    f'value="{i % 100},{i // 100},0"/></transform>{EMITTER}</shape>\n')
        f.write('</scene>\n')


def copies(n, name):
    with open(name + '.obj', 'w') as f:
        f.write('v 0 0 0\nv 1 0 0\nv 0 1 0\n' + 'f 1 2 3\n' * n)
    obj_scene(name)


def polygon(n, name):
    with open(name + '.obj', 'w') as f:
        for i in range(n):
            a = 2 * math.pi * i / n
            f.write(f'v {math.cos(a):.9f} {math.sin(a):.9f} 0\n')
        f.write('f ' + ' '.join(str(i + 1) for i in range(n)) + '\n')
    obj_scene(name)


def nodes(n, name):
    buf = struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack('<4H', 0, 1, 2, 0)
    g = {
        'asset': {'version': '2.0'}, 'scene': 0,
        'scenes': [{'nodes': list(range(n))}],
        'nodes': [{'mesh': 0, 'translation': [i % 1000 * 2, i // 1000 * 2, 0]} for i in range(n)],
        'meshes': [{'primitives': [{'attributes': {'POSITION': 0}, 'indices': 1}]}],
        'accessors': [
            {'bufferView': 0, 'componentType': 5126, 'count': 3, 'type': 'VEC3',
             'min': [0, 0, 0], 'max': [1, 1, 0]},
            {'bufferView': 1, 'componentType': 5123, 'count': 3, 'type': 'SCALAR'}],
        'bufferViews': [{'buffer': 0, 'byteOffset': 0, 'byteLength': 36},
                        {'buffer': 0, 'byteOffset': 36, 'byteLength': 6}],
        'buffers': [{'byteLength': len(buf), 'uri': 'data:application/octet-stream;base64,'
                     + base64.b64encode(buf).decode()}],
    }
    with open(name + '.gltf', 'w') as f:
        json.dump(g, f, separators=(',', ':'))


if __name__ == '__main__':
    kind, n, name = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    {'emitters': emitters, 'copies': copies, 'polygon': polygon, 'nodes': nodes}[kind](n, name)
