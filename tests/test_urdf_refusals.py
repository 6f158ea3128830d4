"""Every URDF robot/body/urdf_read.py refuses, in one line naming the file and the link,
joint or mesh and what was found; what it takes with a warning; xacro."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robot.body.urdf_read import read_urdf
from robot.errors import ConfigError
from tests.urdf_files import CUBE_FACES, cube, inertial, write_stl

ROOT = f'<link name="base">{inertial(0.5)}</link>'


def _leg(joint: str = 'type="revolute"', link: str = "", limit: str = 'lower="-1" upper="1"',
         name: str = "hip") -> str:
    body = link or inertial(0.1, "0 0 -0.03")
    return (f'<link name="leg">{body}</link><joint name="{name}" {joint}><origin xyz="0 0.05 0" '
            f'rpy="0 0 0"/><parent link="base"/><child link="leg"/><axis xyz="0 1 0"/>'
            f'<limit {limit} effort="1" velocity="2"/></joint>')


def _urdf(tmp: Path, body: str, *, name: str = "robot.urdf", head: str = '<robot name="r">') -> Path:
    path = tmp / name
    path.write_text(f"{head}{body}</robot>")
    return path


def _refused(path: Path, *words: str, **kw: object) -> str:
    with pytest.raises(ConfigError) as err:
        read_urdf(path, **kw)  # type: ignore[arg-type]
    text = str(err.value)
    assert "\n" not in text and text.startswith(str(path)), text
    for w in words:
        assert w in text, (w, text)
    return text


@pytest.mark.parametrize("kind", ["prismatic", "planar", "floating"])
def test_joints_the_body_cannot_take(tmp_path: Path, kind: str) -> None:
    path = _urdf(tmp_path, ROOT + _leg(f'type="{kind}"'))
    _refused(path, "joint 'hip'", f"a {kind} joint", "revolute, continuous and fixed")


def test_tree_faults(tmp_path: Path) -> None:
    two_roots = _urdf(tmp_path, ROOT + '<link name="stray"/>', name="a.urdf")
    _refused(two_roots, "exactly one root", "'base', 'stray'")
    loop = ROOT + _leg() + ('<joint name="back" type="fixed"><parent link="leg"/><child link="base"/>'
                            "</joint>")
    _refused(_urdf(tmp_path, loop, name="b.urdf"), "root link, found none", "a loop")
    twice = ROOT + _leg() + ('<joint name="again" type="fixed"><parent link="base"/>'
                             '<child link="leg"/></joint>')
    _refused(_urdf(tmp_path, twice, name="c.urdf"), "joint 'again'", "'leg' already hangs from joint 'hip'")
    undefined = ROOT + _leg().replace('<child link="leg"/>', '<child link="lg"/>')
    _refused(_urdf(tmp_path, undefined, name="d.urdf"), "joint 'hip'", "link 'lg' is not defined")
    _refused(_urdf(tmp_path, ROOT + _leg(joint='type="hinge"'), name="e.urdf"),
             "joint 'hip'", 'type "hinge" is not a URDF joint type')
    _refused(_urdf(tmp_path, ROOT + _leg(limit='lower="1" upper="-1"'), name="f.urdf"),
             "joint 'hip'", "lower is above upper")
    bad_number = ROOT + _leg().replace('xyz="0 1 0"', 'xyz="0 one 0"')
    _refused(_urdf(tmp_path, bad_number, name="g.urdf"), "joint 'hip' <axis>", 'xyz="0 one 0"')


def test_files_that_are_not_urdf(tmp_path: Path) -> None:
    _refused(tmp_path / "none.urdf", "no such URDF file")
    _refused(_urdf(tmp_path, ROOT + "<link", name="broken.urdf"), "not well-formed XML")
    not_urdf = tmp_path / "model.urdf"
    not_urdf.write_text("<mujoco><worldbody/></mujoco>")
    _refused(not_urdf, "not a URDF", "<mujoco>")


def test_a_missing_collision_mesh_is_refused_or_boxed(tmp_path: Path) -> None:
    leg = inertial(0.1, "0.01 0 -0.03", "0.3 0.2 0.1") + (
        '<visual><geometry><mesh filename="package://pkg/meshes/leg_visual.stl"/></geometry></visual>'
        '<collision><geometry><mesh filename="package://pkg/meshes/leg.stl"/></geometry></collision>')
    path = _urdf(tmp_path, ROOT + _leg(link=leg))
    _refused(path, "link 'leg'", "collision mesh 'package://pkg/meshes/leg.stl' not found",
             "--mesh-dir", "--missing-meshes box")
    tree, warnings = read_urdf(path, missing_mesh="box")
    assert len(warnings) == 1 and "link 'leg'" in warnings[0] and "equivalent-inertia box" in warnings[0]
    (box,) = tree.links[1].shapes
    assert box.kind == "box" and box.note.startswith("stand-in")
    # The oracle: the solid box's own inertia (m/12 (b^2 + c^2), ...) turned into the link
    # frame is the link's inertia, and it sits at the centre of mass.
    inert = tree.links[1].inertial
    assert inert is not None
    hx, hy, hz = box.size
    m = inert.mass
    own = np.diag([m * (hy**2 + hz**2) / 3, m * (hx**2 + hz**2) / 3, m * (hx**2 + hy**2) / 3])
    from robot.body.tree import quat_to_matrix
    r = quat_to_matrix(box.quat)
    np.testing.assert_allclose(r @ own @ r.T, inert.matrix(), atol=1e-15)
    np.testing.assert_allclose(box.pos, inert.com, atol=1e-15)
    massless = _urdf(tmp_path, ROOT + _leg(link=leg.split("</inertial>")[1]) , name="m.urdf")
    _refused(massless, "link 'leg'", "no mass to size an equivalent-inertia box", missing_mesh="box")


def test_a_mesh_format_mujoco_does_not_read(tmp_path: Path) -> None:
    (tmp_path / "leg.dae").write_text("<COLLADA/>")
    leg = inertial(0.1) + '<collision><geometry><mesh filename="leg.dae"/></geometry></collision>'
    path = _urdf(tmp_path, ROOT + _leg(link=leg))
    _refused(path, "link 'leg': collision mesh 'leg.dae'", f"{tmp_path / 'leg.dae'}: mesh format .dae",
             "convert it to STL")


def test_zero_mass_on_a_moving_link(tmp_path: Path) -> None:
    empty = _urdf(tmp_path, ROOT + _leg(link=""), name="a.urdf")
    empty.write_text(empty.read_text().replace(inertial(0.1, "0 0 -0.03"), ""))
    _refused(empty, "link 'leg'", "moved by hinge 'hip'", "no mass")
    _refused(empty, "no collision shape", fix_inertia=True)
    zero = inertial(0.0, moments=(0, 0, 0, 0, 0, 0)) + (
        '<collision><origin xyz="0 0 -0.05"/><geometry><box size="0.02 0.03 0.1"/></geometry></collision>')
    path = _urdf(tmp_path, ROOT + _leg(link=zero), name="b.urdf")
    _refused(path, "link 'leg'", "no mass")
    tree, warnings = read_urdf(path, fix_inertia=True)
    fixed = tree.links[1].inertial
    assert fixed is not None
    assert fixed.mass == pytest.approx(1000.0 * 0.02 * 0.03 * 0.1, rel=1e-12)  # 1000 kg/m^3
    np.testing.assert_allclose(fixed.com, (0, 0, -0.05), atol=1e-12)
    np.testing.assert_allclose(fixed.inertia[:3], (fixed.mass * (0.03**2 + 0.1**2) / 12,
                                                    fixed.mass * (0.02**2 + 0.1**2) / 12,
                                                    fixed.mass * (0.02**2 + 0.03**2) / 12), rtol=1e-9)
    assert len(warnings) == 1 and "mass 0 kg -> 0.06 kg" in warnings[0] and "1000 kg/m^3" in warnings[0]


def test_bad_inertia(tmp_path: Path) -> None:
    bad = inertial(0.1, moments=(1e-5, 1e-5, 5e-5, 0, 0, 0))
    path = _urdf(tmp_path, ROOT + _leg(link=bad))
    _refused(path, "link 'leg'", "triangle inequality", "1e-05 + 1e-05 < 5e-05")
    tree, warnings = read_urdf(path, fix_inertia=True)
    assert tree.links[1].inertial is not None
    np.testing.assert_allclose(tree.links[1].inertial.inertia, (7e-5 / 3,) * 3 + (0.0,) * 3, atol=1e-18)
    assert "moments -> (2.333e-05, 2.333e-05, 2.333e-05)" in warnings[0]


def test_mimic_is_taken_as_independent(tmp_path: Path) -> None:
    mimic = _leg().replace("</joint>", '<mimic joint="other" multiplier="-1"/></joint>')
    tree, warnings = read_urdf(_urdf(tmp_path, ROOT + mimic))
    assert tree.links[1].joint is not None and tree.links[1].joint.name == "hip"
    assert warnings == ["joint 'hip' mimics joint 'other': taken as an independent hinge (the "
                        "simulation drives it on its own)"]


XACRO_HEAD = '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'


def test_xacro_is_expanded_as_ros_would(tmp_path: Path) -> None:
    write_stl(tmp_path / "meshes" / "leg.stl", cube(0.02), CUBE_FACES)
    macro = ('<xacro:property name="width" value="0.05"/>'
             '<xacro:macro name="leg" params="side y">'
             f'<link name="${{side}}_leg">{inertial(0.1, "0 0 -0.03")}<collision><geometry>'
             '<mesh filename="meshes/leg.stl"/></geometry></collision></link>'
             '<joint name="${side}_hip" type="revolute"><origin xyz="0 ${y*width} 0"/>'
             '<parent link="base"/><child link="${side}_leg"/><axis xyz="0 1 0"/>'
             '<limit lower="-1" upper="1" effort="1" velocity="2"/></joint></xacro:macro>'
             '<xacro:leg side="l" y="1"/><xacro:leg side="r" y="-1"/>')
    path = _urdf(tmp_path, ROOT + macro, name="robot.urdf.xacro", head=XACRO_HEAD)
    tree, warnings = read_urdf(path)
    assert warnings == []
    assert [link.name for link in tree.links] == ["base", "l_leg", "r_leg"]
    assert [link.pos for link in tree.links[1:]] == [(0.0, 0.05, 0.0), (0.0, -0.05, 0.0)]
    assert all(len(link.shapes) == 1 for link in tree.links[1:])


def test_xacro_that_needs_ros(tmp_path: Path) -> None:
    body = '<xacro:include filename="$(find my_robot_description)/urdf/leg.xacro"/>' + ROOT
    path = _urdf(tmp_path, body, name="robot.urdf.xacro", head=XACRO_HEAD)
    _refused(path, "$(find PKG) needs ROS", "xacro robot.urdf.xacro > robot.urdf")
    broken = _urdf(tmp_path, '<link name="${no_such_property}"/>', name="b.xacro", head=XACRO_HEAD)
    _refused(broken, "xacro cannot expand it", "no_such_property")
