"""URDFs written for the tests in the style of each exporter, with the small meshes they
reference (binary and ASCII STL, OBJ), and the copy MuJoCo's own URDF parser is given
as the oracle.

MuJoCo's URDF parser differs from what a builder's exporter expects, so the oracle copy
(``mujoco_copy``) works around it: it fuses fixed joints by default and then fuses the
root into the world (the root's mass vanishes), so the copy sets fusestatic="false"; it
mangles ``package://`` (to ``package:/``) and reads no ASCII STL, so each collision mesh
is given by its absolute path, an ASCII STL as a binary copy; it would compute a mass
for links without an inertial from their geoms, so inertiafromgeom="false"; visual
elements are dropped (their meshes may be missing).
"""

from __future__ import annotations

import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
CUBE_FACES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
              (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
TETRA_FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def cube(size: float, centre: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    return (CUBE - 0.5) * size + np.asarray(centre)


def write_stl(path: Path, verts: np.ndarray, faces: list[tuple[int, int, int]], *,
              ascii_: bool = False) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if ascii_:
        lines = ["solid test"]
        for f in faces:
            lines += ["  facet normal 0 0 0", "    outer loop"]
            lines += [f"      vertex {verts[i][0]:.9e} {verts[i][1]:.9e} {verts[i][2]:.9e}" for i in f]
            lines += ["    endloop", "  endfacet"]
        path.write_text("\n".join(lines + ["endsolid test", ""]))
        return path
    out = bytearray(b"binary STL written by the biped tests".ljust(80, b" "))
    out += struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for i in f:
            out += struct.pack("<3f", *verts[i])
        out += b"\0\0"
    path.write_bytes(bytes(out))
    return path


def write_obj(path: Path, verts: np.ndarray, faces: list[tuple[int, int, int]]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ["# OBJ written by the biped tests", "o part"]
    lines += [f"v {x:.9f} {y:.9f} {z:.9f}" for x, y, z in verts]
    lines += ["vn 0 0 1"] + [f"f {a + 1}//1 {b + 1}//1 {c + 1}//1" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def inertial(mass: float, com: str = "0 0 0", rpy: str = "0 0 0",
             moments: tuple[float, ...] | None = None) -> str:
    """An <inertial>; by default the moments of a part of about 65 x 55 x 40 mm."""
    ixx, iyy, izz, ixy, ixz, iyz = moments or tuple(
        mass * m for m in (4e-4, 5e-4, 6e-4, 2e-5, -1e-5, 1e-5))
    return (f'<inertial><origin xyz="{com}" rpy="{rpy}"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/>'
            "</inertial>")


def onshape_style(root: Path) -> tuple[Path, dict[str, Path]]:
    """onshape-to-robot: parts' names as links, joints named by the user (dof names), z
    axes with odd rpy origins, frames as massless links on fixed joints, package://
    assets/ meshes (binary STL), a visual mesh that is missing, joint_properties."""
    refs = {"package://assets/trunk.stl": write_stl(root / "assets" / "trunk.stl",
                                                    cube(0.08, (0.0, 0.0, 0.02)), CUBE_FACES),
            "package://assets/thigh.stl": write_stl(root / "assets" / "thigh.stl",
                                                    TETRA * 0.05 + (-0.01, -0.01, -0.06), TETRA_FACES)}
    frame = ('<inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="1e-9"/><inertia ixx="0" '
             'ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>')
    parts = ['<robot name="onshape">',
             f'<link name="trunk">{inertial(0.9, "0.001 0 0.03")}'
             '<visual><geometry><mesh filename="package://assets/trunk_visual.stl"/></geometry></visual>'
             '<collision><origin xyz="0 0 0" rpy="0 -0 0"/><geometry><mesh '
             'filename="package://assets/trunk.stl"/></geometry></collision></link>',
             f'<link name="imu">{frame}</link>',
             '<joint name="imu_frame" type="fixed"><origin xyz="0.01 0 0.05" rpy="3.14159 -0 1.5708"/>'
             '<parent link="trunk"/><child link="imu"/><axis xyz="0 0 0"/></joint>']
    for side, y in (("left", 0.045), ("right", -0.045)):
        parts += [
            f'<link name="{side}_hip">{inertial(0.07, "0 0.002 -0.01")}</link>',
            f'<joint name="{side}_hip_yaw" type="revolute"><origin xyz="0.003 {y} -0.02" '
            'rpy="3.14159 1.2e-16 -1.5708"/><parent link="trunk"/><child link="' + side + '_hip"/>'
            '<axis xyz="0 0 1"/><limit effort="2.9" velocity="6.2" lower="-1.2" upper="0.9"/>'
            '<joint_properties friction="0.0"/></joint>',
            f'<link name="{side}_thigh">{inertial(0.12, "0.01 0 -0.04", "0.2 0 0")}'
            '<collision><origin xyz="0 0.002 0" rpy="0.3 -0.1 2.0"/><geometry>'
            '<mesh filename="package://assets/thigh.stl"/></geometry></collision></link>',
            f'<joint name="{side}_hip_pitch" type="revolute"><origin xyz="0.01 -0.004 0.035" '
            'rpy="-1.5708 0.4 3.14159"/><parent link="' + side + '_hip"/><child link="' + side
            + '_thigh"/><axis xyz="0 0 1"/><limit effort="2.9" velocity="6.2" lower="-2" upper="2"/>'
            '</joint>',
            f'<link name="{side}_shin">{inertial(0.1, "0 0 -0.05")}</link>',
            f'<joint name="{side}_knee" type="revolute"><origin xyz="0 -0.1 0.003" rpy="0 0 0.7"/>'
            '<parent link="' + side + '_thigh"/><child link="' + side + '_shin"/><axis xyz="0 0 1"/>'
            '<limit effort="2.9" velocity="6.2" lower="-0.1" upper="2.4"/></joint>',
            f'<link name="{side}_foot_frame">{frame}</link>',
            f'<joint name="{side}_foot_frame_frame" type="fixed"><origin xyz="0.002 -0.11 0.01" '
            'rpy="1.5708 0 -0.7"/><parent link="' + side + '_shin"/><child link="' + side
            + '_foot_frame"/><axis xyz="0 0 0"/></joint>']
    return _write(root / "robot.urdf", parts), refs


def fusion_style(root: Path, *, empty_base: bool = True) -> tuple[Path, dict[str, Path]]:
    """fusion2urdf (as ROS's xacro expands it): ``base_link``, ``Revolute_N`` and
    ``Rigid_N`` joints, the xacro namespace on the root, mm meshes with
    scale="0.001 0.001 0.001" under package://NAME_description/meshes/, odd rpy, a
    continuous joint, an ASCII STL and an OBJ."""
    mesh, pkg = root / "bot_description" / "meshes", "package://bot_description/meshes/"
    refs = {pkg + "body_1.stl": write_stl(mesh / "body_1.stl", cube(60.0, (0.0, 0.0, 30.0)),
                                          CUBE_FACES, ascii_=True),
            pkg + "leg_1.stl": write_stl(mesh / "leg_1.stl", TETRA * 40.0 + (-5.0, -5.0, -45.0),
                                         TETRA_FACES),
            pkg + "wheel_1.obj": write_obj(mesh / "wheel_1.obj", cube(20.0), CUBE_FACES)}
    base = "" if empty_base else inertial(0.3, "0 0 0.01")
    parts = ['<robot name="bot" xmlns:xacro="http://www.ros.org/wiki/xacro">',
             f'<link name="base_link">{base}</link>',
             f'<link name="body_1">{inertial(1.2, "0.0 0.0 0.03")}'
             '<collision><origin xyz="0.0 0.0 0.0" rpy="0 0 0"/><geometry><mesh filename='
             '"package://bot_description/meshes/body_1.stl" scale="0.001 0.001 0.001"/></geometry>'
             '</collision></link>',
             '<joint name="Rigid_1" type="fixed"><origin xyz="0.0 0.0 0.05" rpy="0 0 0"/>'
             '<parent link="base_link"/><child link="body_1"/></joint>']
    for k, (y, rpy) in enumerate(((0.04, "0.1 -0.35 0.02"), (-0.04, "-1.5708 0 3.14159")), start=1):
        parts += [
            f'<link name="leg_{k}">{inertial(0.2, "0.0 0.0 -0.03")}'
            '<collision><origin xyz="0.0 0.0 0.0" rpy="0 0 0"/><geometry><mesh filename='
            '"package://bot_description/meshes/leg_1.stl" scale="0.001 0.001 0.001"/></geometry>'
            '</collision></link>',
            f'<joint name="Revolute_{k}" type="revolute"><origin xyz="0.0 {y} -0.01" rpy="{rpy}"/>'
            f'<parent link="body_1"/><child link="leg_{k}"/><axis xyz="0.0 -1.0 0.0"/>'
            '<limit upper="1.570796" lower="-1.570796" effort="100" velocity="100"/></joint>',
            f'<link name="wheel_{k}">{inertial(0.05, "0 0 0", moments=(1e-5, 1e-5, 1.5e-5, 0, 0, 0))}'
            '<collision><origin xyz="0 0 0" rpy="1.5708 0 0"/><geometry><mesh filename='
            '"package://bot_description/meshes/wheel_1.obj" scale="0.001 0.001 0.001"/></geometry>'
            '</collision></link>',
            f'<joint name="Revolute_{k + 2}" type="continuous"><origin xyz="0.01 0.0 -0.06" '
            f'rpy="0 0.25 0"/><parent link="leg_{k}"/><child link="wheel_{k}"/>'
            '<axis xyz="0.0 0.6 0.8"/></joint>']
    return _write(root / "bot_description" / "urdf" / "bot.urdf", parts), refs


def solidworks_style(root: Path) -> tuple[Path, dict[str, Path]]:
    """sw_urdf_exporter: ``base_link``, ``Link1``.., ``joint1``.., package://ASM/meshes/
    NAME.STL in upper case (the files on disk in lower case), effort and velocity 0,
    inertials with full origins, visuals with materials, a sensor link on a fixed joint."""
    mesh = root / "asm" / "meshes"
    refs = {"package://asm/meshes/base_link.STL": write_stl(
                mesh / "base_link.stl", cube(0.05, (0.0, 0.0, 0.025)), CUBE_FACES),
            "package://asm/meshes/Link1.STL": write_stl(
                mesh / "link1.stl", TETRA * 0.03 + (0.0, 0.0, -0.04), TETRA_FACES, ascii_=True)}
    vis = ('<visual><origin xyz="0 0 0" rpy="0 0 0"/><geometry><mesh filename="package://asm/meshes/'
           '{0}.STL"/></geometry><material name=""><color rgba="0.79 0.82 0.93 1"/></material></visual>')
    parts = ['<?xml version="1.0" encoding="utf-8"?>',
             "<!-- This URDF was automatically created by SolidWorks to URDF Exporter! -->",
             '<robot name="asm">',
             f'<link name="base_link">{inertial(0.5, "-0.0011 0.0002 0.024", "0.01 0.02 0.03")}'
             + vis.format("base_link") + '<collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry>'
             '<mesh filename="package://asm/meshes/base_link.STL"/></geometry></collision></link>']
    parent = "base_link"
    for k, rpy in enumerate(("1.5708 0 0", "-1.5708 -0.5236 3.1416", "0 1.5708 0"), start=1):
        parts += [f'<link name="Link{k}">{inertial(0.08, "0.002 -0.01 0.015", "0.5 0.1 -0.2")}'
                  + vis.format(f"Link{k}") + '<collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry>'
                  '<mesh filename="package://asm/meshes/Link1.STL"/></geometry></collision></link>',
                  f'<joint name="joint{k}" type="revolute"><origin xyz="0.012 -0.003 0.031" rpy="{rpy}"/>'
                  f'<parent link="{parent}"/><child link="Link{k}"/><axis xyz="0 0 -1"/>'
                  '<limit lower="-2.0944" upper="2.0944" effort="0" velocity="0"/></joint>']
        parent = f"Link{k}"
    parts += ['<link name="sensor"><inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="0.01"/>'
              '<inertia ixx="1e-7" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial>'
              '<collision><origin xyz="0 0 0.005" rpy="0 0 0.3"/><geometry><box size="0.02 0.01 0.004"/>'
              '</geometry></collision></link>',
              '<joint name="sensor_joint" type="fixed"><origin xyz="0.01 0.02 -0.05" rpy="0.3 0.2 0.1"/>'
              '<parent link="Link3"/><child link="sensor"/><axis xyz="0 0 0"/></joint>']
    return _write(root / "asm" / "urdf" / "asm.urdf", parts), refs


def _write(path: Path, parts: list[str]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(parts + ["</robot>", ""]))
    return path


def mujoco_copy(urdf: Path, meshes: dict[str, Path], out: Path, *, fuse: bool = False) -> Path:
    """A copy of ``urdf`` MuJoCo's parser reads as the exporter meant it (see the module
    docstring); ``meshes``: each collision mesh reference → the file it is. ``fuse``:
    MuJoCo fuses the fixed joints itself; the root then gets a floating joint from a new
    world link so that it is not fused into MuJoCo's world."""
    tree = ET.parse(urdf)
    robot = tree.getroot()
    for link in robot.findall("link"):
        for vis in link.findall("visual"):
            link.remove(vis)
    for mesh in robot.iter("mesh"):
        src = meshes[mesh.get("filename", "")]
        if src.read_bytes()[:5] == b"solid":
            binary = out.parent / f"{src.stem}_binary.stl"
            write_stl(binary, *_ascii_faces(src))
            src = binary
        mesh.set("filename", str(src.resolve()))
    compiler = ET.SubElement(ET.SubElement(robot, "mujoco"), "compiler")
    compiler.attrib.update({"fusestatic": "true" if fuse else "false", "discardvisual": "true",
                            "inertiafromgeom": "false", "strippath": "false"})
    if fuse:
        children = {j.find("child").get("link") for j in robot.findall("joint")}  # type: ignore[union-attr]
        root = next(ln.get("name") for ln in robot.findall("link") if ln.get("name") not in children)
        ET.SubElement(robot, "link", name="oracle_world")
        joint = ET.SubElement(robot, "joint", name="oracle_float", type="floating")
        ET.SubElement(joint, "parent", link="oracle_world")
        ET.SubElement(joint, "child", link=str(root))
    tree.write(out)
    return out


def _ascii_faces(path: Path) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    pts = [[float(v) for v in line.split()[1:4]] for line in path.read_text().splitlines()
           if line.strip().startswith("vertex")]
    return np.array(pts), [(i, i + 1, i + 2) for i in range(0, len(pts), 3)]
