"""Map files through Python: a map written by C++ (mvog_ray_export, mvog::saveMap) loads and saves
to the same bytes (so the same FNV-1a checksum), the map Python builds from the same rays is that
file byte for byte, paths may be str or pathlib.Path, a truncated file raises MapFileError; map
updates keep a MapMirror equal to its source."""

import struct

import numpy as np
import pytest

import mvog


def scans_of(directory):
    """The exported scans: (origin, hits) pairs, hits an (N, 3) float32 view of hits.npy."""
    origins = np.load(directory / "origins.npy")
    sizes = np.load(directory / "scan_sizes.npy")
    hits = np.load(directory / "hits.npy")
    ends = np.cumsum(sizes)
    return [(origin, hits[end - size:end]) for origin, size, end in zip(origins, sizes, ends)]


def test_a_cpp_map_loads_and_saves_to_the_same_bytes(reference, tmp_path):
    directory, _ = reference
    written_by_cpp = (directory / "map.mvog").read_bytes()
    loaded = mvog.load_map(directory / "map.mvog")          # pathlib.Path
    assert mvog.serialize_map(loaded) == written_by_cpp
    mvog.save_map(loaded, str(tmp_path / "again.mvog"))     # str
    saved = (tmp_path / "again.mvog").read_bytes()
    assert saved[-8:] == written_by_cpp[-8:]  # the checksum
    assert saved == written_by_cpp
    assert mvog.serialize_map(mvog.deserialize_map(saved)) == saved


def test_the_map_python_builds_from_the_same_rays_is_the_cpp_map(reference):
    directory, printed = reference
    world = mvog.Map(mvog.MapConfig(resolution=0.1))
    inserted = 0
    for origin, hits in scans_of(directory):
        inserted += world.insert_scan(origin, hits).inserted
    assert inserted == printed["readings"]
    assert mvog.serialize_map(world) == (directory / "map.mvog").read_bytes()


def test_a_truncated_or_corrupt_file_raises_map_file_error(tmp_path):
    world = mvog.Map()
    world.insert_scan([0, 0, 1], np.random.default_rng(2).uniform(-3, 3, (500, 3)))
    mvog.save_map(world, tmp_path / "whole.mvog")
    data = (tmp_path / "whole.mvog").read_bytes()
    truncated = tmp_path / "truncated.mvog"
    truncated.write_bytes(data[:len(data) // 2])
    with pytest.raises(mvog.MapFileError):
        mvog.load_map(truncated)
    with pytest.raises(OSError):  # MapFileError is an OSError
        mvog.load_map(tmp_path / "missing.mvog")
    corrupt = bytearray(data)
    corrupt[100] ^= 0xFF
    with pytest.raises(mvog.MapFileError):
        mvog.deserialize_map(bytes(corrupt))
    with pytest.raises(mvog.MapFileError):
        mvog.deserialize_map(b"")


def test_save_map_writes_the_format_header(tmp_path):
    world = mvog.Map()
    world.insert_scan([0, 0, 0], np.array([[1.0, 0.0, 0.0]]))
    mvog.save_map(world, tmp_path / "one.mvog")
    data = (tmp_path / "one.mvog").read_bytes()
    assert data[:8] == b"MVOGMAP\0"
    assert struct.unpack_from("<I", data, 8)[0] == mvog.MAP_FORMAT_VERSION


def test_a_mirror_follows_its_source_by_updates():
    source = mvog.Map()
    source.insert_scan([0, 0, 1], np.array([[2.0, 0.0, 0.0], [0.0, 2.0, 0.5]]))
    mirror = mvog.MapMirror()
    assert mirror.source_revision == 0
    full = mvog.map_update(source, 0)
    assert mvog.read_map_update_info(full).full
    assert mirror.apply(full).status == mvog.MapUpdateStatus.APPLIED
    assert mvog.serialize_map(mirror.map) == mvog.serialize_map(source)
    since = source.revision
    source.insert_scan([0, 0, 1], np.array([[-2.0, 0.0, 0.0]]))
    source.decay(0.9)
    update = mvog.map_update(source, since)
    info = mvog.read_map_update_info(update)
    assert not info.full and info.from_revision == since and info.to_revision == source.revision
    assert mirror.apply(update).status == mvog.MapUpdateStatus.APPLIED
    assert mirror.source_revision == source.revision
    assert mvog.serialize_map(mirror.map) == mvog.serialize_map(source)
    # An update that starts after what the mirror holds: missed, not applied.
    since = source.revision
    source.insert_scan([0, 0, 1], np.array([[0.0, -2.0, 0.0]]))
    later = source.revision
    source.insert_scan([0, 0, 1], np.array([[0.0, -3.0, 0.0]]))
    assert mirror.apply(mvog.map_update(source, later)).status == mvog.MapUpdateStatus.MISSED
    assert mirror.apply(mvog.map_update(source, since)).status == mvog.MapUpdateStatus.APPLIED
    with pytest.raises(mvog.MapFileError):
        mirror.apply(b"MVOGUPD\0" + bytes(10))
    assert mvog.serialize_map(mirror.map) == mvog.serialize_map(source)
