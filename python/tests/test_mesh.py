"""Mesh files through the C++ readers and writers: round trips are bit-identical, the reader
agrees with an independent parse, malformed files raise ValueError naming file and line."""

import numpy as np
import pytest

import clothcd


def test_obj_and_ply_round_trips_are_bit_identical(tmp_path):
    F, V, _ = clothcd.procedural.crumpled_sheet(9, 2)
    V = V * np.pi  # digits that need all 17 places
    for ext in ("obj", "ply", "OBJ"):
        path = tmp_path / f"m.{ext}"
        clothcd.write_mesh(path, V, F)
        V2, F2 = clothcd.read_mesh(path)
        assert V2.dtype == np.float64 and F2.dtype == np.int32
        assert V2.flags.c_contiguous and V2.shape == V.shape
        assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_obj_reader_agrees_with_a_plain_parse(tmp_path):
    text = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nv 2 2 2\nf 1 2 3 4\nf 2 5 3\n"
    path = tmp_path / "q.obj"
    path.write_text(text)
    V, F = clothcd.read_mesh(path)
    want_v = [[float(x) for x in line.split()[1:]] for line in text.splitlines() if line.startswith("v ")]
    assert V.tolist() == want_v
    # Polygons fan-triangulated from their first corner, 0-based.
    assert F.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]


def test_malformed_files_raise_value_error_naming_file_and_line(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(ValueError, match=r"bad\.obj:4"):
        clothcd.read_mesh(path)
    with pytest.raises(clothcd.InputError):
        clothcd.read_mesh(path)
    with pytest.raises(ValueError, match="missing.ply"):
        clothcd.read_mesh(tmp_path / "missing.ply")
    with pytest.raises(ValueError, match="unknown mesh format"):
        clothcd.read_mesh(tmp_path / "mesh.stl")


def test_write_refuses_bad_meshes_and_leaves_no_file(tmp_path):
    F, V, _ = clothcd.procedural.stacked_sheets(3)
    bad = V.copy()
    bad[5, 1] = np.nan
    path = tmp_path / "out.ply"
    with pytest.raises(ValueError, match="vertex 5"):
        clothcd.write_mesh(path, bad, F)
    F_bad = F.copy()
    F_bad[2, 0] = len(V)
    with pytest.raises(ValueError, match="face 2"):
        clothcd.write_mesh(path, V, F_bad)
    assert not path.exists()
    assert list(tmp_path.iterdir()) == []


def test_mesh_edges_numbering():
    F = np.array([[0, 1, 2], [2, 1, 3]])
    # Sorted by (larger id, smaller id), smaller first in each row.
    assert clothcd.mesh_edges(F).tolist() == [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
