#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (test/fuzz/corpus/<target>/), deterministically.

map_file: maps in the format of include/mvog/map_io.h (valid ones, and a few refused ones).
map_update: map updates in the format of include/mvog/map_io.h, of the small map that
fuzz_map_update.cpp's mirrors start from (valid ones, and a few refused ones).
conversions: inputs in the layout documented at the top of test/fuzz/fuzz_conversions.cpp.
Run it again after changing either format; the files are small and committed.
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
NAN = float('nan')
INF = float('inf')


def fnv1a64(data):
    h = 0xcbf29ce484222325
    for b in data:
        h ^= b
        h = (h * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


def map_file(cells, resolution=0.1, max_coordinate=10000.0, version=1):
    """cells: [(x, y, [(bottom, top, mass)...positive], [(...)...negative])]"""
    volumes = sum(len(p) + len(n) for _, _, p, n in cells)
    out = b'MVOGMAP\0' + struct.pack('<IIddQQQQ', version, 64, resolution, max_coordinate,
                                     len(cells), volumes, 0, 0)
    for x, y, positive, negative in cells:
        out += struct.pack('<iiII', x, y, len(positive), len(negative))
        for bottom, top, mass in positive + negative:
            out += struct.pack('<fff', bottom, top, mass)
    return out + struct.pack('<Q', fnv1a64(out))


def map_update(tiles, removed=(), full=False, source=1, from_revision=0, to_revision=1,
               mass_unit=1.0, unit_exponent=0, resolution=1.0, max_coordinate=1000.0, rules=7,
               out_of_range_free_length=2.0):
    """tiles: [(tile_x, tile_y, exponent, [(x, y, [(bottom, top, mass)...positive], [...])])]"""
    cells = sum(len(c) for _, _, _, c in tiles)
    volumes = sum(len(p) + len(n) for _, _, _, c in tiles for _, _, p, n in c)
    out = b'MVOGUPD\0' + struct.pack('<IIddIdIQQQdqQQQQQ', 1, 128, resolution, max_coordinate,
                                      rules, out_of_range_free_length, 1 if full else 0, source,
                                      from_revision, to_revision, mass_unit, unit_exponent,
                                      len(removed), len(tiles), cells, volumes, 0)
    for tile_x, tile_y in removed:
        out += struct.pack('<ii', tile_x, tile_y)
    for tile_x, tile_y, exponent, tile_cells in tiles:
        out += struct.pack('<iiiI', tile_x, tile_y, exponent, len(tile_cells))
        for x, y, positive, negative in tile_cells:
            out += struct.pack('<iiII', x, y, len(positive), len(negative))
            for bottom, top, mass in positive + negative:
                out += struct.pack('<fff', bottom, top, mass)
    return out + struct.pack('<Q', fnv1a64(out))


def pose(x=0.0, y=0.0, z=0.0, roll=0.0, pitch=0.0, yaw=0.0):
    return struct.pack('<6f', x, y, z, roll, pitch, yaw)


def scan(ranges, angle_min=0.0, angle_increment=math.pi / 2, range_min=0.1, range_max=10.0,
         max_free_range=0.0, beams=None, intensities=0, options=1, sensor=None):
    beams = len(ranges) if beams is None else beams
    out = struct.pack('<BB', 0, options) + (sensor or pose(0.5, -0.5, 1.0, 0.0, 0.1, 0.3))
    out += struct.pack('<6f', angle_min, angle_min + angle_increment * max(beams - 1, 0),
                       angle_increment, range_min, range_max, max_free_range)
    out += struct.pack('<IH', beams, intensities)
    return out + struct.pack('<%df' % len(ranges), *ranges)


FLOAT32, FLOAT64, INT32 = 7, 8, 5
NAMES = {'x': 0, 'y': 1, 'z': 2, 'rgb': 3, 'intensity': 4, 'xx': 5}


def cloud(points, fields, point_step, width, row_padding=0, big_endian=False, options=1,
          sensor=None, height=None, data=None):
    height = len(points) // width if height is None else height
    row_step = (point_step * width + row_padding) & 0xFFFFFFFF
    out = struct.pack('<BB', 1, options) + (sensor or pose(0.0, 0.0, 1.2, 0.0, 0.0, 1.0))
    out += struct.pack('<BIIIIB', 1 if big_endian else 0, height, width, point_step, row_step,
                       len(fields))
    for name, offset, datatype in fields:
        out += struct.pack('<BIBI', NAMES[name], offset, datatype, 1)
    if data is None:
        body = bytearray(b'\xab' * (row_step * height))
        order = '>' if big_endian else '<'
        for k, point in enumerate(points):
            start = (k // width) * row_step + (k % width) * point_step
            for name, offset, datatype in fields:
                if name not in 'xyz' or len(name) != 1:
                    continue
                value = point['xyz'.index(name)]
                code = 'd' if datatype == FLOAT64 else 'f'
                size = 8 if datatype == FLOAT64 else 4
                body[start + offset:start + offset + size] = struct.pack(order + code, value)
        data = bytes(body)
    return out + data


XYZ32 = [('x', 0, FLOAT32), ('y', 4, FLOAT32), ('z', 8, FLOAT32)]
ENCODINGS = {'16UC1': 0, '32FC1': 1, 'mono16': 2, '32FC2': 3, 'rgb8': 4}


def depth_image(depths, width, encoding='32FC1', big_endian=False, step=None, info_size=None,
                k=(40.0, 40.0, None, None), stride=1, no_return_length=0.0, options=1, data=None):
    """depths: row after row, metres (millimetres for 16UC1); k: fx, fy, cx, cy (None: centre)."""
    height = len(depths) // width if width else 0
    pixel = 2 if encoding == '16UC1' else 4
    step = width * pixel if step is None else step
    info_width, info_height = (width, height) if info_size is None else info_size
    fx, fy, cx, cy = k
    cx = (width - 1) / 2.0 if cx is None else cx
    cy = (height - 1) / 2.0 if cy is None else cy
    out = struct.pack('<BB', 2, options) + pose(0.0, 0.0, 1.5, -math.pi / 2, 0.0, -math.pi / 2)
    out += struct.pack('<BBIIIII4dBf', ENCODINGS[encoding], 1 if big_endian else 0, width,
                       height, step, info_width, info_height, fx, fy, cx, cy, stride - 1,
                       no_return_length)
    if data is None:
        body = bytearray(b'\xab' * (step * height))
        code = ('>' if big_endian else '<') + ('H' if pixel == 2 else 'f')
        for n, depth in enumerate(depths):
            struct.pack_into(code, body, (n // width) * step + (n % width) * pixel, depth)
        data = bytes(body)
    return out + data


def main():
    maps = {
        'empty.mvog': map_file([]),
        'one_volume.mvog': map_file([(0, 0, [(0.0, 1.0, 1.0)], [])]),
        'two_cells.mvog': map_file([(0, 0, [(2.0, 3.0, 1.0)], [(-1.0, 1.5, 2.5)]),
                                    (-5, 7, [], [(0.0, 4.0, 4.0), (6.0, 8.0, 2.0)])]),
        'coarse_far.mvog': map_file([(99, -100, [(-3.0, -1.5, 0.5)], [(10.0, 12.0, 2.0)])],
                                    resolution=1.0, max_coordinate=100.0),
        'decayed.mvog': map_file([(3, 4, [(0.5, 1.5, 1e-30)], [(-4.0, 0.0, 3e-31)]),
                                  (4, 4, [(0.0, 1.0, 0.0)], [])]),
        'refused_checksum.mvog': map_file([(0, 0, [(0.0, 1.0, 1.0)], [])])[:-1] + b'\0',
        'refused_version.mvog': map_file([], version=2),
    }
    for name, data in maps.items():
        with open(os.path.join(HERE, 'corpus', 'map_file', name), 'wb') as f:
            f.write(data)

    # The small map of fuzz_map_update.cpp, at revision 5, then what changed after.
    small_tiles = [(0, 0, 0, [(3, 4, [(0.0, 1.0, 2.0)], [(-4.0, -1.0, 3.0)]),
                              (5, 4, [], [(2.0, 5.0, 3.0)])]),
                   (1, 0, 0, [(17, 0, [(1.0, 2.0, 1.0)], [])]),
                   (-1, 2, 0, [(-3, 40, [(0.0, 2.0, 2.0)], [])])]
    changed = [(0, 0, 0, [(3, 4, [(0.0, 1.0, 4.0)], [(-4.0, -1.0, 3.0)]),
                          (5, 4, [], [(2.0, 5.0, 3.0)])])]
    many = [(3.0 * k, 3.0 * k + 1.0, 1.0) for k in range(300)]  # a tile of wide counts
    updates = {
        'full.mvogupd': map_update(small_tiles, full=True, to_revision=5),
        'removed_and_changed.mvogupd': map_update(changed, removed=[(1, 0)], from_revision=5,
                                                  to_revision=7, mass_unit=0.75),
        'decay_only.mvogupd': map_update([], from_revision=7, to_revision=8, mass_unit=0.625,
                                         unit_exponent=-3),
        'wide_tile.mvogupd': map_update([(2, 2, 0, [(33, 40, many, [(-9.0, -2.0, 7.0)])])],
                                        from_revision=5, to_revision=9),
        'extreme_exponents.mvogupd': map_update([(0, 0, 1 << 24, [(1, 1, [(0.0, 1.0, 3e38)], [])])],
                                                from_revision=5, to_revision=10,
                                                unit_exponent=-(1 << 24)),
        'refused_checksum.mvogupd': map_update(changed, from_revision=5, to_revision=6)[:-1] + b'\0',
        'refused_map_file.mvogupd': map_file([(0, 0, [(0.0, 1.0, 1.0)], [])]),
    }
    for name, data in updates.items():
        with open(os.path.join(HERE, 'corpus', 'map_update', name), 'wb') as f:
            f.write(data)

    far = 1e7  # 10,000 km
    inputs = {
        'scan_four_beams': scan([1.0, 2.0, 0.5, 10.0]),
        'scan_special_ranges': scan([NAN, INF, -INF, -1.0, 0.05, 1e30, 3.0, 12.0],
                                    angle_increment=0.2, max_free_range=4.0),
        'scan_one_beam_no_increment': scan([2.0], angle_increment=0.0),
        'scan_negative_increment': scan([1.0, 1.5, 2.0], angle_min=1.0, angle_increment=-0.5,
                                        options=1 | 2 | 8),
        'scan_bad_limits': scan([1.0, 1.0], range_min=5.0, range_max=1.0),
        'scan_nan_angle': scan([1.0, 1.0], angle_min=NAN),
        'scan_no_beams': scan([]),
        'scan_many_beams_few_bytes': scan([1.5], beams=3000, angle_increment=1e-3, options=0),
        'scan_intensities_mismatch': scan([1.0, 2.0, 3.0], intensities=7, angle_increment=0.1),
        'cloud_xyz32': cloud([(1.0, 2.0, 0.5), (3.0, -1.0, 1.5), (0.5, 0.5, 0.0),
                              (-2.0, -2.0, 2.0)], XYZ32, 12, 4),
        'cloud_float64_bigendian_padded': cloud(
            [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0, 1.0)],
            [('rgb', 0, FLOAT32), ('x', 5, FLOAT64), ('y', 13, FLOAT64), ('z', 21, FLOAT32)],
            32, 2, row_padding=3, big_endian=True, options=1 | 4),
        'cloud_nan_and_far_points': cloud([(NAN, 0.0, 0.0), (INF, 1.0, 1.0), (far, far, 0.0),
                                           (2.0, 2.0, 1.0)], XYZ32, 12, 4),
        'cloud_integer_fields': cloud([(1.0, 1.0, 1.0)], [('x', 0, INT32), ('y', 4, INT32),
                                                          ('z', 8, INT32)], 12, 1),
        'cloud_missing_z': cloud([(1.0, 1.0, 1.0)], XYZ32[:2], 12, 1),
        'cloud_field_beyond_step': cloud([(1.0, 1.0, 1.0)], XYZ32, 8, 1, data=b'\0' * 12),
        'cloud_short_data': cloud([], XYZ32, 12, 100, height=100, data=b'\0' * 120),
        'cloud_absurd_size': cloud([], XYZ32, 12, 0xFFFFFFFF, height=0xFFFFFFFF, data=b''),
        'cloud_empty': cloud([], XYZ32, 12, 0, height=0, data=b''),
        'depth_millimetres': depth_image([1500, 0, 2000, 2500, 3000, 0, 1200, 900, 4000], 3,
                                         encoding='16UC1'),
        'depth_metres_special_values': depth_image(
            [2.0, 0.0, NAN, INF, -INF, -1.0, 3.5, 1e30], 4, no_return_length=5.0,
            options=1 | 2),
        'depth_metres_padded_stride': depth_image([1.0 + 0.1 * n for n in range(20)], 5,
                                                  step=27, stride=2, options=1 | 8),
        'depth_no_return_without_length': depth_image([INF] * 6, 3),
        'depth_wrong_encoding': depth_image([1.0] * 4, 2, encoding='rgb8'),
        'depth_big_endian': depth_image([1000] * 4, 2, encoding='16UC1', big_endian=True),
        'depth_step_too_small': depth_image([1.0] * 4, 2, step=7, data=b'\0' * 14),
        'depth_data_short': depth_image([1.0] * 4, 2, data=b'\0' * 15),
        'depth_zero_k': depth_image([1.0] * 4, 2, k=(0.0, 0.0, 0.0, 0.0)),
        'depth_nan_k': depth_image([1.0] * 4, 2, k=(NAN, 40.0, 0.5, 0.5)),
        'depth_camera_info_other_size': depth_image([1.0] * 4, 2, info_size=(4, 4)),
    }
    for name, data in inputs.items():
        with open(os.path.join(HERE, 'corpus', 'conversions', name), 'wb') as f:
            f.write(data)


if __name__ == '__main__':
    main()
