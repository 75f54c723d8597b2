"""Mesh I/O: single meshes, collections (folder / npz), labels, and every bad input."""

import numpy as np
import pytest
from geometry_fixtures import icosphere, tube

from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.geometry.collection_io import natural_key, read_collection, write_collection
from meshvae_lib.geometry.mesh_checks import remove_unreferenced_vertices, validate_mesh
from meshvae_lib.geometry.mesh_files import read_mesh, write_mesh


@pytest.fixture
def sphere():
    return icosphere(1)


@pytest.mark.parametrize("suffix", [".obj", ".off", ".ply"])
def test_write_read_round_trip_keeps_order_and_precision(tmp_path, sphere, suffix):
    V, F = sphere
    V = V + 1e-9 * np.arange(len(V))[:, None]  # digits beyond float32
    path = write_mesh(tmp_path / f"m{suffix}", V, F)
    V2, F2 = read_mesh(path)
    assert V2.dtype == np.float64 and F2.dtype == np.int64
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_array_equal(V2, V)


def test_read_obj_with_texture_coordinates_keeps_vertex_order(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\n" \
           "f 4/1 2/2 3/1\nf 1/1 3/2 2/1\nf 1/1 2/1 4/2\nf 1/2 4/1 3/1\n"
    (tmp_path / "t.obj").write_text(text)
    V, F = read_mesh(tmp_path / "t.obj")
    np.testing.assert_array_equal(V, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    np.testing.assert_array_equal(F, [[3, 1, 2], [0, 2, 1], [0, 1, 3], [0, 3, 2]])


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such mesh file"):
        read_mesh(tmp_path / "nope.obj")
    with pytest.raises(FileNotFoundError, match="no such collection"):
        read_collection(tmp_path / "nope")


def test_quads_are_refused_or_triangulated_on_request(tmp_path):
    (tmp_path / "q.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    with pytest.raises(ValueError, match="4 corners"):
        read_mesh(tmp_path / "q.obj")
    V, F = read_mesh(tmp_path / "q.obj", triangulate=True)
    assert F.shape == (2, 3) and len(V) == 4
    (tmp_path / "q.off").write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    with pytest.raises(ValueError, match="4 corners"):
        read_mesh(tmp_path / "q.off")


def test_nan_coordinates(tmp_path):
    (tmp_path / "n.obj").write_text("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match=r"NaN or infinite.*vertex 1"):
        read_mesh(tmp_path / "n.obj")


def test_unreferenced_vertices_error_and_fix(tmp_path):
    (tmp_path / "u.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 2 3\n")
    with pytest.raises(ValueError, match=r"1 unreferenced vertices.*\[3\]"):
        read_mesh(tmp_path / "u.obj")
    V, F = read_mesh(tmp_path / "u.obj", validate=False)
    Vk, Fk, kept = remove_unreferenced_vertices(V, F)
    np.testing.assert_array_equal(kept, [0, 1, 2])
    validate_mesh(Vk, Fk)


def test_zero_area_and_repeated_vertex_faces(tmp_path):
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]])
    F = np.array([[0, 1, 2], [0, 1, 3]])  # second face is collinear
    with pytest.raises(ValueError, match=r"1 zero-area faces \(first: face 1"):
        validate_mesh(V, F)
    validate_mesh(V, F, allow_degenerate=True)
    write_mesh(tmp_path / "z.obj", V, F)
    with pytest.raises(ValueError, match="zero-area"):
        read_mesh(tmp_path / "z.obj")
    read_mesh(tmp_path / "z.obj", allow_degenerate=True)
    with pytest.raises(ValueError, match="repeat a vertex"):
        validate_mesh(V, np.array([[0, 1, 2], [0, 0, 3]]))
    with pytest.raises(ValueError, match=r"must lie in \[0, 3\]"):
        validate_mesh(V, np.array([[0, 1, 4]]))
    with pytest.raises(ValueError, match=r"\(n_faces, 3\), got \(1, 4\)"):
        validate_mesh(V, np.array([[0, 1, 2, 3]]))


def test_unreadable_file(tmp_path):
    (tmp_path / "bad.off").write_text("this is not a mesh\n")
    with pytest.raises(ValueError, match="bad.off"):
        read_mesh(tmp_path / "bad.off")


def test_folder_collection_natural_order_and_labels(tmp_path, sphere):
    V, F = sphere
    for k in (10, 2, 1):
        write_mesh(tmp_path / f"pose{k}.obj", V * (1 + k / 10), F)
    (tmp_path / "labels.csv").write_text("name,speed,kind\npose1,1.5,walk\npose2,2,run\n"
                                         "pose10,3,walk\n")
    (tmp_path / "notes.txt").write_text("ignored")
    col = read_collection(tmp_path)
    assert col.names == ["pose1", "pose2", "pose10"]
    assert natural_key("pose2") < natural_key("pose10")
    np.testing.assert_allclose(col.vertices[2], V * 2.0)
    np.testing.assert_allclose(col.labels["speed"], [1.5, 2.0, 3.0])
    assert col.labels["kind"].tolist() == ["walk", "run", "walk"]


def test_folder_labels_errors(tmp_path, sphere):
    V, F = sphere
    write_mesh(tmp_path / "a.obj", V, F)
    write_mesh(tmp_path / "b.obj", V, F)
    (tmp_path / "labels.csv").write_text("name,x\na,1\n")
    with pytest.raises(ValueError, match=r"no row for mesh\(es\) \['b'\]"):
        read_collection(tmp_path)
    (tmp_path / "labels.csv").write_text("name,x\na,1\nb,2\nc,3\n")
    with pytest.raises(ValueError, match="not in the folder"):
        read_collection(tmp_path)
    (tmp_path / "labels.csv").write_text("file,x\na,1\nb,2\n")
    with pytest.raises(ValueError, match="first column must be 'name'"):
        read_collection(tmp_path)


def test_folder_with_different_connectivity_names_the_file(tmp_path, sphere):
    V, F = sphere
    write_mesh(tmp_path / "1.obj", V, F)
    F2 = F.copy()
    F2[5] = F2[5, [0, 2, 1]]
    write_mesh(tmp_path / "2.obj", V, F2)
    with pytest.raises(ValueError, match=r"2\.obj: its faces differ from those of 1\.obj.*face 5"):
        read_collection(tmp_path)
    Vt, Ft = tube(6, 3)
    write_mesh(tmp_path / "2.obj", Vt, Ft)
    with pytest.raises(ValueError, match=r"2\.obj: has 26 vertices but 1\.obj has 42"):
        read_collection(tmp_path)


def test_empty_folder(tmp_path):
    with pytest.raises(ValueError, match="holds no mesh files"):
        read_collection(tmp_path)


@pytest.mark.parametrize("target", ["c.npz", "folder"])
def test_collection_round_trip(tmp_path, sphere, target):
    V, F = sphere
    verts = np.stack([V, 1.1 * V, V + 1e-12])
    labels = {"speed": np.array([1.0, 2.5, 3.0]), "kind": np.array(["a", "b", "a"]),
              "id": np.array([3, 1, 2])}
    names = ["walk 1", "walk/2", "run"]  # not usable as file names, not in natural order
    write_collection(tmp_path / target, verts, F, names=names, labels=labels)
    col = read_collection(tmp_path / target)
    np.testing.assert_array_equal(col.vertices, verts)
    np.testing.assert_array_equal(col.faces, F)
    assert len(col.names) == 3
    if target.endswith(".npz"):
        assert col.names == names
    else:  # numbered files keep the order and show the name
        assert col.names[0].startswith("0000_walk") and col.names[2].endswith("run")
    for key, val in labels.items():
        assert col.labels[key].tolist() == val.tolist()
    # a MeshCollection can be written directly
    write_collection(tmp_path / "again.npz", col)
    assert read_collection(tmp_path / "again.npz").names == col.names


def test_npz_collection_errors(tmp_path, sphere):
    V, F = sphere
    np.savez(tmp_path / "a.npz", vertices=V[None], faces=np.concatenate([F, F[:, :1]], 1))
    with pytest.raises(ValueError, match=r"'faces' must be triangles.*\(80, 4\)"):
        read_collection(tmp_path / "a.npz")
    np.savez(tmp_path / "b.npz", verts=V[None], faces=F)
    with pytest.raises(ValueError, match="has no 'vertices'"):
        read_collection(tmp_path / "b.npz")
    bad = np.stack([V, V])
    bad[1, 4, 0] = np.inf
    np.savez(tmp_path / "c.npz", vertices=bad, faces=F, names=np.array(["x", "y"]))
    with pytest.raises(ValueError, match=r"mesh 'y' \(index 1\) has NaN or infinite"):
        read_collection(tmp_path / "c.npz")
    np.savez(tmp_path / "d.npz", vertices=np.stack([V, V]), faces=F, label_x=np.arange(3))
    with pytest.raises(ValueError, match=r"'label_x' must have shape \(2,\)"):
        read_collection(tmp_path / "d.npz")
    (tmp_path / "e.npz").write_text("garbage")
    with pytest.raises(ValueError, match="cannot be read"):
        read_collection(tmp_path / "e.npz")


def test_npz_float32_and_int32_are_converted(tmp_path, sphere):
    V, F = sphere
    np.savez(tmp_path / "f.npz", vertices=V[None].astype(np.float32), faces=F.astype(np.int32))
    col = read_collection(tmp_path / "f.npz")
    assert col.vertices.dtype == np.float64 and col.faces.dtype == np.int64
    assert col.names == ["0000"]


def test_mesh_collection_validates_shapes():
    with pytest.raises(ValueError, match=r"\(n_meshes, n_vertices, 3\)"):
        MeshCollection(np.zeros((4, 3)), np.zeros((1, 3), int))
    with pytest.raises(ValueError, match="2 names for 1 meshes"):
        MeshCollection(np.zeros((1, 4, 3)), np.zeros((1, 3), int), ["a", "b"])


def test_collection_subset_keeps_names_labels_and_order(sphere):
    V, F = sphere
    verts = np.stack([V + i for i in range(5)])
    coll = MeshCollection(verts, F, [f"m{i}" for i in range(5)], {"k": np.arange(5) * 10})
    sub = coll.subset([3, 1, 3])
    assert sub.names == ["m3", "m1", "m3"] and sub.labels["k"].tolist() == [30, 10, 30]
    assert np.array_equal(sub.vertices, verts[[3, 1, 3]]) and sub.faces is coll.faces
    mask = np.array([True, False, False, False, True])
    assert coll.subset(mask).names == ["m0", "m4"]
    for bad, msg in (([5], r"\[0, 4\], got range \[5, 5\]"), ([], "at least one"), ([0.5], "integers"),
                     (np.ones(3, bool), r"shape \(5,\)")):
        with pytest.raises(ValueError, match=msg):
            coll.subset(bad)
