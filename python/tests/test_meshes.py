"""Meshes from arrays and from files the test writes (binary and ASCII STL,
OBJ): hull distances against analytic answers, a decomposition that follows
a concave mesh, and every bad input. On a Client and on Local alike."""

from __future__ import annotations

import math
import pathlib
import struct
from typing import Any

import numpy as np
import pytest

import gjkd

IDENTITY = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]


def cube(half: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed cube of half side ``half``: 8 vertices, 12 triangles."""
    v = np.array(
        [[x, y, z] for z in (-half, half) for y in (-half, half) for x in (-half, half)],
        dtype=np.float64,
    )
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))], dtype=np.int32)
    return v, t


def write_binary_stl(path: pathlib.Path, v: np.ndarray, t: np.ndarray) -> None:
    out = bytearray(b"gjkd test".ljust(80, b" "))
    out += struct.pack("<I", len(t))
    for tri in t:
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for i in tri:
            out += struct.pack("<3f", *v[i])
        out += struct.pack("<H", 0)
    path.write_bytes(bytes(out))


def write_ascii_stl(path: pathlib.Path, v: np.ndarray, t: np.ndarray) -> None:
    lines = ["solid test"]
    for tri in t:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {v[i][0]} {v[i][1]} {v[i][2]}" for i in tri]
        lines += ["endloop", "endfacet"]
    lines.append("endsolid test")
    path.write_text("\n".join(lines) + "\n")


def write_obj(path: pathlib.Path, v: np.ndarray, t: np.ndarray) -> None:
    lines = [f"v {x} {y} {z}" for x, y, z in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in t]
    path.write_text("\n".join(lines) + "\n")


def at(x: float, y: float = 0.0, z: float = 0.0) -> list[float]:
    return [x, y, z, 0.0, 0.0, 0.0, 1.0]


@pytest.mark.parametrize("fmt", ["binary.stl", "ascii.stl", "obj"])
def test_mesh_file_hull_distance(objects: Any, tmp_path: pathlib.Path, fmt: str) -> None:
    v, t = cube(0.5)
    path = tmp_path / f"cube.{fmt}"
    {"binary.stl": write_binary_stl, "ascii.stl": write_ascii_stl, "obj": write_obj}[fmt](
        path, v, t
    )
    # Scaled 2x along x: the cube spans x in [-1, 1].
    info = gjkd.MeshInfo()
    mesh = objects.register_mesh_file(path, scale=[2.0, 1.0, 1.0], info=info)
    assert (info.pieces, info.deviation) == (1, 0.0)
    ball = objects.register_sphere(0.25, pose=at(3.0))
    assert abs(objects.distance(mesh, ball).distance - 1.75) < 1e-9
    # Along y the scale is 1: the face is at 0.5.
    objects.set_pose(ball, at(0.0, 2.0))
    assert abs(objects.distance(mesh, ball).distance - 1.25) < 1e-9
    # A string path works too, and a uniform scale.
    other = objects.register_mesh_file(str(path), scale=3.0, pose=at(0.0, 0.0, 10.0))
    objects.set_pose(ball, at(0.0, 0.0, 13.0))
    assert abs(objects.distance(other, ball).distance - (3.0 - 1.5 - 0.25)) < 1e-9


def test_mesh_arrays_hull_matches_polytope(objects: Any) -> None:
    rng = np.random.default_rng(7)
    cloud = rng.normal(size=(200, 3))
    tris = np.array([[0, 1, 2]], dtype=np.int64)
    mesh = objects.register_mesh(cloud, tris, name=None, pose=at(0.5, 0.2))
    poly = objects.register_polytope(cloud, pose=at(0.5, 0.2))
    ball = objects.register_sphere(0.1, pose=at(5.0, 1.0, -2.0))
    # The hull of the points is the polytope of the points.
    d_mesh = objects.distance(mesh, ball).distance
    d_poly = objects.distance(poly, ball).distance
    assert abs(d_mesh - d_poly) < 1e-9
    # Brute force: the distance from the ball's centre to the hull is at
    # most the distance to the nearest vertex.
    nearest = np.min(np.linalg.norm(cloud + [0.5, 0.2, 0.0] - [5.0, 1.0, -2.0], axis=1))
    assert d_mesh <= nearest - 0.1 + 1e-9


def l_shape() -> tuple[np.ndarray, np.ndarray]:
    """An L-shaped prism: the union of [0,3]x[0,1] and [0,1]x[0,3] in x, y,
    extruded over z in [0, 1]: concave, the notch towards (3, 3) is empty
    (the hull's slanted face is x + y = 4)."""
    outline = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]
    n = len(outline)
    v = np.array([[x, y, z] for z in (0.0, 1.0) for x, y in outline], dtype=np.float64)
    tris: list[tuple[int, int, int]] = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, j, n + j), (i, n + j, n + i)]
    # Caps, as a fan of the two rectangles.
    for a, b, c, d in ((0, 1, 2, 3), (0, 3, 4, 5)):
        tris += [(a, c, b), (a, d, c), (n + a, n + b, n + c), (n + a, n + c, n + d)]
    return v, np.array(tris, dtype=np.int64)


def test_decomposition_follows_a_concave_mesh(objects: Any) -> None:
    v, t = l_shape()
    hull_info, parts_info = gjkd.MeshInfo(), gjkd.MeshInfo()
    assert (hull_info.pieces, hull_info.deviation) == (0, 0.0)
    hull = objects.register_mesh(v, t, info=hull_info)
    parts = objects.register_mesh(v, t, decompose=32, info=parts_info)
    assert (hull_info.pieces, hull_info.deviation) == (1, 0.0)
    # A concave L needs two pieces at least. The hull fills the notch up to
    # x + y = 4, sqrt(2) beyond the mesh's inner corner: the pieces reach
    # out less than that.
    assert parts_info.pieces >= 2
    assert 0.0 <= parts_info.deviation < math.sqrt(2.0)
    # A failed registration leaves the info as it was.
    before = (parts_info.pieces, parts_info.deviation)
    with pytest.raises(gjkd.InvalidInput):
        objects.register_mesh(v, t, decompose=0, info=parts_info)
    assert (parts_info.pieces, parts_info.deviation) == before
    assert "pieces=" in repr(parts_info)
    # A small ball in the notch: inside the hull, clear of the mesh.
    ball = objects.register_sphere(0.1, pose=at(1.8, 1.8, 0.5))
    assert objects.distance(hull, ball).distance == 0.0
    # The true distance is from (1.8, 1.8) to the corner (1, 1): the pieces
    # may reach a little beyond the mesh, never past the hull.
    true = math.hypot(0.8, 0.8) - 0.1
    d = objects.distance(parts, ball).distance
    assert 0.5 * true < d <= true + 1e-9


def test_mesh_errors(objects: Any, tmp_path: pathlib.Path) -> None:
    v, t = cube()
    InvalidInput = gjkd.InvalidInput

    def raises(call: Any, field: str, index: "int | None" = None) -> None:
        with pytest.raises(InvalidInput) as e:
            call()
        assert e.value.field == field, e.value
        assert e.value.index == index, e.value

    raises(lambda: objects.register_mesh(np.zeros((0, 3))), "vertices")
    bad = v.copy()
    bad[3, 1] = math.nan
    raises(lambda: objects.register_mesh(bad, t), "vertices")
    raises(lambda: objects.register_mesh(v[:, :2]), "vertices")
    wrong = t.copy()
    wrong[5, 2] = 8
    raises(lambda: objects.register_mesh(v, wrong), "triangles", 5)
    raises(lambda: objects.register_mesh(v, t.astype(np.float64)), "triangles")
    raises(lambda: objects.register_mesh(v, np.array([[0, -1, 2]])), "triangles", 0)
    raises(lambda: objects.register_mesh(v, decompose=16), "triangles")
    raises(lambda: objects.register_mesh(v, t, decompose=0), "decompose")
    raises(lambda: objects.register_mesh(v, t, scale=0.0), "scale")
    raises(lambda: objects.register_mesh(v, t, scale=[1.0, math.inf, 1.0]), "scale")
    raises(lambda: objects.register_mesh(v, t, scale="big"), "scale")
    raises(lambda: objects.register_mesh_file(tmp_path / "missing.stl"), "path")
    junk = tmp_path / "junk.stl"
    junk.write_text("not a mesh at all")
    raises(lambda: objects.register_mesh_file(junk), "path")
    with pytest.raises(gjkd.InvalidInput) as e:
        objects.register_mesh(v, t, pose=[math.nan, 0, 0, 0, 0, 0, 1])
    assert e.value.code == gjkd.ErrorCode.NON_FINITE_POSE
    # Nothing was registered by any of these; a good mesh still is.
    a = objects.register_mesh(v, t, name="mesh-errors-cube")
    assert objects.lookup("mesh-errors-cube") == a
    with pytest.raises(gjkd.Refused) as e:
        objects.register_mesh(v, t, name="mesh-errors-cube")
    assert e.value.code == gjkd.ErrorCode.NAME_TAKEN
    objects.remove(a)


def test_cylinders_against_closed_forms(objects: Any) -> None:
    """A cylinder of radius 0.5, half-height 1 about z (an exact shape, no
    polytope), against a ball: side, cap and rim distances in closed form."""
    cyl = objects.register_cylinder(0.5, 1.0)
    rounded = objects.register_cylinder(0.5, 1.0, 0.1, pose=at(10.0))
    ball = objects.register_sphere(0.25)
    for where, want in (
        ((2.0, 0.0, 0.3), 1.25),
        ((0.0, -2.0, -0.5), 1.25),
        ((0.2, 0.1, 3.0), 1.75),
        ((2.0, 0.0, 2.0), math.hypot(1.5, 1.0) - 0.25),
        ((math.sqrt(0.5) * 2, math.sqrt(0.5) * 2, 0.0), 2.0 - 0.5 - 0.25),
    ):
        objects.set_pose(ball, at(*where))
        assert abs(objects.distance(cyl, ball).distance - want) < 1e-9, where
        objects.set_pose(ball, at(where[0] + 10.0, where[1], where[2]))
        assert abs(objects.distance(rounded, ball).distance - (want - 0.1)) < 1e-9, where
    # A cylinder piece in a compound, offset along x.
    shape = gjkd.Shape.cylinder(0.5, 1.0)
    assert shape.kind == "cylinder" and shape.radius == 0.0 and shape.vertices.shape == (0, 3)
    comp = objects.register_compound([(at(0.0, 0.0, 20.0), shape)])
    objects.set_pose(ball, at(2.0, 0.0, 20.0))
    assert abs(objects.distance(comp, ball).distance - 1.25) < 1e-9
    for bad in ((-0.5, 1.0, 0.0), (0.5, math.nan, 0.0), (0.5, 1.0, -1.0)):
        with pytest.raises(gjkd.InvalidInput) as e:
            objects.register_cylinder(*bad)
        assert e.value.code == gjkd.ErrorCode.INVALID_RADIUS, bad
