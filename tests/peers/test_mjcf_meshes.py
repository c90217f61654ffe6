"""MJCF meshes, shells and springdamper joints weighed by tumble and by MuJoCo's compiler.

Each case is a small model written here: a mesh from a file (STL, OBJ, MSH) or from ``vertex``/``face``, in each of
MuJoCo's four ``<mesh inertia>`` modes, scaled, moved, mirrored; primitives fitted to a mesh; shells; a joint whose
spring and damper come from ``springdamper``. The body's mass, centre of mass and inertia must equal MuJoCo's compiled
``body_mass``, ``body_ipos`` and ``body_inertia`` to round-off (MuJoCo's eigen-solver stops at off-diagonal terms of
1e-12 m⁵ per unit density, far below these meshes' 1e-3 m⁵).
"""

from __future__ import annotations

import numpy as np
import pytest

from tumble.mass import mesh as exact_mesh
from tumble.models.mjcf import read_mjcf
from tumble.rotation import quat_to_matrix

mujoco = pytest.importorskip("mujoco")
trimesh = pytest.importorskip("trimesh")
pytestmark = pytest.mark.peers

# An L-shaped prism: not convex, so MuJoCo's legacy mode (every pyramid counted positive from the faces' centroid)
# weighs more than the solid, and the convex hull more still.
_L_OUTLINE = [(0.0, 0.0), (0.4, 0.0), (0.4, 0.1), (0.1, 0.1), (0.1, 0.3), (0.0, 0.3)]


def _l_prism() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and outward faces of the L outline extruded 0.2 m along z."""
    n = len(_L_OUTLINE)
    vertices = np.array([(x, y, z) for z in (0.0, 0.2) for x, y in _L_OUTLINE]) + [0.05, -0.02, 0.1]
    # the caps: fans from a corner that sees the whole outline (the L's inner corner, index 3)
    bottom = [(3, (3 + k + 1) % n, (3 + k) % n) for k in range(1, n - 1)]
    top = [(n + 3, n + (3 + k) % n, n + (3 + k + 1) % n) for k in range(1, n - 1)]
    sides = [tri for k in range(n) for tri in ((k, (k + 1) % n, n + (k + 1) % n), (k, n + (k + 1) % n, n + k))]
    return vertices, np.array(bottom + top + sides)


def _text(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _faces(faces) -> str:
    return " ".join(str(int(i)) for i in np.ravel(faces))


def _compare(xml: str, rtol: float = 1e-12) -> None:
    """Every body's mass, centre and inertia tensor in tumble's description equal MuJoCo's compiled model's."""
    description, model = read_mjcf(xml), mujoco.MjModel.from_xml_string(xml)
    for index, body in enumerate(description.bodies, start=1):
        mp = body.mass_properties
        assert mp.mass == pytest.approx(model.body_mass[index], rel=rtol)
        np.testing.assert_allclose(mp.com, model.body_ipos[index], rtol=0, atol=1e-12)
        rotation = quat_to_matrix(model.body_iquat[index])
        tensor = rotation @ np.diag(model.body_inertia[index]) @ rotation.T
        np.testing.assert_allclose(mp.inertia, tensor, rtol=0, atol=1e-9 * np.abs(tensor).max())


def _one_body(asset: str, geom: str, compiler: str = "") -> str:
    return (f"<mujoco><compiler {compiler}/><asset>{asset}</asset><worldbody><body pos='0 0 1'><freejoint/>"
            f"{geom}</body></worldbody></mujoco>")  # fmt: skip


@pytest.mark.parametrize("inertia", ["legacy", "exact", "convex", "shell"])
def test_a_non_convex_mesh_weighs_what_mujoco_weighs_in_each_inertia_mode(inertia):
    vertices, faces = _l_prism()
    asset = f"<mesh name='l' vertex='{_text(vertices)}' face='{_faces(faces)}' inertia='{inertia}'/>"
    _compare(_one_body(asset, "<geom type='mesh' mesh='l' pos='0.1 0 0' euler='10 20 30' density='700'/>"))


def test_legacy_mode_overcounts_a_non_convex_mesh_and_exact_mode_is_the_solid():
    vertices, faces = _l_prism()
    written = f"vertex='{_text(vertices)}' face='{_faces(faces)}'"
    masses = {}
    for mode in ("legacy", "exact", "convex"):
        xml = _one_body(f"<mesh name='l' {written} inertia='{mode}'/>", "<geom type='mesh' mesh='l'/>")
        masses[mode] = read_mjcf(xml).bodies[0].mass_properties
    solid = exact_mesh(vertices.astype(np.float32).astype(float), faces, density=1000.0)
    assert masses["exact"].isclose(solid, rtol=1e-12)
    assert solid.mass == pytest.approx(1000.0 * (0.4 * 0.1 + 0.1 * 0.2) * 0.2, rel=1e-6)
    hull_volume = 0.2 * (0.4 * 0.1 + 0.1 * 0.2 + 0.5 * 0.3 * 0.2)  # the L plus the triangle its hull adds
    assert masses["convex"].mass == pytest.approx(1000.0 * hull_volume, rel=1e-6)
    assert solid.mass < masses["legacy"].mass


@pytest.mark.parametrize("kind", ["sphere", "capsule", "cylinder", "ellipsoid", "box"])
def test_a_primitive_that_names_a_mesh_is_fitted_to_its_box_of_equal_inertia(kind):
    vertices, faces = _l_prism()
    asset = f"<mesh name='l' vertex='{_text(vertices)}' face='{_faces(faces)}'/>"
    _compare(_one_body(asset, f"<geom type='{kind}' mesh='l' fitscale='1.3' quat='0.9 0.1 0.3 -0.2'/>"))
    fitted = read_mjcf(_one_body(asset, f"<geom type='{kind}' mesh='l'/>")).bodies[0].geoms[0]
    model = mujoco.MjModel.from_xml_string(_one_body(asset, f"<geom type='{kind}' mesh='l'/>"))
    np.testing.assert_allclose(fitted.size, model.geom_size[0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(fitted.pos, model.geom_pos[0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("suffix", [".stl", ".obj"])
def test_mesh_files_in_meshdir_scaled_and_moved(tmp_path, suffix):
    vertices, faces = _l_prism()
    (tmp_path / "parts").mkdir()
    trimesh.Trimesh(vertices, faces, process=False).export(tmp_path / "parts" / f"ell{suffix}")
    asset = f"<mesh file='ell{suffix}' scale='1.5 -0.8 2' refpos='0.01 0.02 -0.03'/>"
    xml = _one_body(asset, "<geom type='mesh' mesh='ell' pos='0 0.1 0' density='2500'/>", "meshdir='parts'")
    (tmp_path / "model.xml").write_text(xml)
    description = read_mjcf(tmp_path / "model.xml")
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "model.xml"))
    mp = description.bodies[0].mass_properties
    assert mp.mass == pytest.approx(model.body_mass[1], rel=1e-12)
    np.testing.assert_allclose(mp.com, model.body_ipos[1], rtol=0, atol=1e-12)
    assert description.meshes["ell"].source == str((tmp_path / "parts" / f"ell{suffix}").resolve())


def test_a_mujoco_msh_file_and_assetdir(tmp_path):
    vertices, faces = _l_prism()
    (tmp_path / "assets").mkdir()
    header = np.array([len(vertices), 0, 0, len(faces)], np.int32)
    data = header.tobytes() + vertices.astype(np.float32).tobytes() + faces.astype(np.int32).tobytes()
    (tmp_path / "assets" / "ell.msh").write_bytes(data)
    xml = _one_body("<mesh file='ell.msh'/>", "<geom type='mesh' mesh='ell'/>", "assetdir='assets'")
    (tmp_path / "model.xml").write_text(xml)
    assert read_mjcf(tmp_path / "model.xml").bodies[0].mass_properties.mass == pytest.approx(
        mujoco.MjModel.from_xml_path(str(tmp_path / "model.xml")).body_mass[1], rel=1e-12)  # fmt: skip


def test_vertices_without_faces_are_their_convex_hull_and_a_given_mass_is_kept():
    rng = np.random.default_rng(3)
    cloud = rng.normal(size=(40, 3)) * [0.1, 0.2, 0.05]
    asset = f"<mesh name='cloud' vertex='{_text(cloud)}'/>"
    _compare(_one_body(asset, "<geom type='mesh' mesh='cloud' mass='2.5' pos='0.3 0 0'/>"))


@pytest.mark.parametrize(
    "geom", ["type='sphere' size='0.3'", "type='box' size='0.1 0.2 0.3' pos='0.1 0.2 0' euler='0 30 60'",
             "type='capsule' size='0.1 0.2' pos='0.1 0.2 0' euler='0 30 60'",
             "type='cylinder' fromto='0 0 0 0.2 0.1 0.4' size='0.05'", "type='box' size='0.1 0.2 0.3' mass='3'",
             "type='ellipsoid' size='0.1 0.2 0.3' euler='10 20 30'", "type='ellipsoid' size='3 2 1' mass='7'"],
)  # fmt: skip
def test_shell_primitives_carry_their_mass_on_the_surface(geom):
    _compare(_one_body("", f"<geom {geom} shellinertia='true'/>"))


def test_the_dog_weighs_what_mujoco_weighs():
    """dm_control's dog: 162 bone meshes (legacy mode, MuJoCo's default) and capsules, 62 bodies: each body's mass
    and centre equal MuJoCo's to round-off, its inertia to MuJoCo's eigen-solver threshold."""
    import importlib.util
    import os

    spec = importlib.util.find_spec("dm_control")
    if spec is None:
        pytest.skip("dm_control is not installed")
    path = os.path.join(os.path.dirname(spec.origin), "suite", "dog.xml")
    with pytest.warns(UserWarning):
        description = read_mjcf(path)
    model = mujoco.MjModel.from_xml_path(path)
    assert len(description.meshes) == model.nmesh
    masses = np.array([b.mass_properties.mass for b in description.bodies])
    np.testing.assert_allclose(masses, model.body_mass[1:], rtol=1e-12)
    np.testing.assert_allclose([b.mass_properties.com for b in description.bodies], model.body_ipos[1:], atol=1e-12)


def test_springdamper_sizes_the_spring_and_damper_from_the_joints_effective_mass():
    xml = """<mujoco><worldbody><body><joint name="swing" axis="0 1 0" springdamper="0.2 0.7" armature="0.3"/>
      <geom type="box" size="0.1 0.2 0.3" pos="0 0 -0.5"/>
      <body pos="0 0 -1"><joint name="slide" type="slide" axis="1 0 0" springdamper="0.1 2"/>
        <geom type="sphere" size="0.1"/></body></body></worldbody></mujoco>"""
    description, model = read_mjcf(xml), mujoco.MjModel.from_xml_string(xml)
    joints = [body.joints[0] for body in description.bodies]
    np.testing.assert_allclose([j.stiffness for j in joints], np.atleast_2d(model.jnt_stiffness.T)[0], rtol=1e-12)
    np.testing.assert_allclose([j.damping for j in joints], model.dof_damping, rtol=1e-12)
