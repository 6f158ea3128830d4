"""RobotConfig → MJCF (MuJoCo Menagerie conventions): ``robot.xml`` plus ``scene.xml``.

robot.xml: compiler/option, ``<default>`` classes (the robot's; ``visual``, ``collision``
and the contact classes), the body tree (robot/config/body_tree.py: the box model or the
imported body, in the robot's terms, written by sim/mujoco/mjcf_body.py; free joint
``root`` on the ``torso`` body, whose frame is the pelvis frame), position actuators named
after their joints, IMU sensors, sole and hand sites, and a ``home`` keyframe: the robot's
rest pose standing with the lowest sole point at z = 0. scene.xml includes robot.xml and
adds floor, light, skybox and the tracking camera ``track``. Every robot, box model or
imported, is written the same way, and what ``biped mjcf`` writes is what is simulated.

Servo model (``sim.mujoco.servo_law``, written per joint by
``sim.mujoco.mjcf_robot.servo_attributes``): each actuator is the firmware's position law at
the robot's gains through the motor at the supply voltage (kp, kv, force range = stall
torque), each joint carries the back-EMF and gearbox damping, the gearbox friction and the
rotor's armature, as with the torque on.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np
import numpy.typing as npt

from robot.config.body_tree import robot_tree, stand_height
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.files.atomic import write_text
from sim.mujoco.geoms import foot_geoms, geom_points
from sim.mujoco.mjcf_body import add_worldbody, has_visuals
from sim.mujoco.mjcf_robot import add_actuators_and_sensors, add_assets, add_defaults, fmt

if TYPE_CHECKING:
    from sim.mujoco.world import World

ROBOT_FILE = "robot.xml"
SCENE_FILE = "scene.xml"
DEFAULT_TIMESTEP = 0.002  # [s]


@dataclass(frozen=True)
class Mjcf:
    """The two MJCF documents for one robot (``scene`` includes ``robot.xml``)."""

    robot: str
    scene: str

    def write(self, out_dir: str | Path) -> tuple[Path, Path]:
        """Write robot.xml and scene.xml into ``out_dir`` (created); returns their paths."""
        out = Path(out_dir)
        try:
            out.mkdir(parents=True, exist_ok=True)
            robot_path, scene_path = out / ROBOT_FILE, out / SCENE_FILE
            write_text(robot_path, self.robot)
            write_text(scene_path, self.scene)
        except OSError as e:
            raise ConfigError(f"--out {out}: cannot write MJCF files: {e.strerror}") from e
        return robot_path, scene_path

    def model(self) -> mujoco.MjModel:
        """Compile the scene (robot included) into a model."""
        return _compile(self.scene, {ROBOT_FILE: self.robot.encode()})


def _compile(xml: str, assets: Mapping[str, bytes] | None = None) -> mujoco.MjModel:
    try:
        return mujoco.MjModel.from_xml_string(xml, dict(assets or {}))
    except ValueError as e:
        raise ConfigError(f"MJCF: MuJoCo cannot compile the generated model: {e}") from e


def _to_string(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def robot_xml(robot: RobotConfig, *, timestep: float = DEFAULT_TIMESTEP,
              home: npt.NDArray[np.float64] | None = None,
              ctrl: npt.NDArray[np.float64] | None = None) -> str:
    """The robot MJCF; ``home`` (qpos) adds the ``home`` keyframe with ``ctrl`` (default:
    its joints, in actuator order)."""
    tree = robot_tree(robot)
    root = ET.Element("mujoco", model=robot.name)
    # every link's mass is its own inertial (none from the shapes)
    ET.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    ET.SubElement(root, "option", timestep=fmt(timestep), integrator="implicitfast")
    add_defaults(root, robot, drawn=not has_visuals(tree))
    add_assets(root)
    add_worldbody(root, tree, childclass=robot.name, height0=stand_height(robot))
    add_actuators_and_sensors(root, robot)
    if home is not None:
        keyframe = ET.SubElement(root, "keyframe")
        ET.SubElement(keyframe, "key", name="home", qpos=fmt(*home),
                      ctrl=fmt(*(home[7:] if ctrl is None else ctrl)))
    return _to_string(root)


def _look_at(eye: tuple[float, float, float], target: tuple[float, float, float]) -> str:
    """Camera ``xyaxes`` looking from ``eye`` at ``target`` with world z up."""
    f = np.subtract(target, eye)
    f = f / np.linalg.norm(f)
    x = np.cross(f, (0.0, 0.0, 1.0))
    x = x / np.linalg.norm(x)
    y = np.cross(x, f)
    return fmt(*x, *y)


def scene_xml(robot: RobotConfig, *, world: World | None = None) -> str:
    """Floor (checker), light, skybox and the ``track`` camera; includes robot.xml.
    ``world``: tilt the floor and add bumps (``sim.mujoco.world_scene``)."""
    g = robot.geometry
    height = g.thigh + g.shin + g.ankle_height + g.torso_height  # overall height [m]
    root = ET.Element("mujoco", model=f"{robot.name} scene")
    ET.SubElement(root, "include", file=ROBOT_FILE)
    ET.SubElement(root, "statistic", center=fmt(0, 0, height / 2), extent=fmt(1.5 * height))
    visual = ET.SubElement(root, "visual")
    ET.SubElement(visual, "headlight", diffuse="0.6 0.6 0.6", ambient="0.3 0.3 0.3",
                  specular="0 0 0")
    ET.SubElement(visual, "rgba", haze="0.15 0.25 0.35 1")
    ET.SubElement(visual, "global", azimuth="-130", elevation="-20", offwidth="1920",
                  offheight="1080")
    asset = ET.SubElement(root, "asset")
    ET.SubElement(asset, "texture", type="skybox", builtin="gradient", rgb1="0.3 0.5 0.7",
                  rgb2="0 0 0", width="512", height="3072")
    ET.SubElement(asset, "texture", type="2d", name="groundplane", builtin="checker",
                  mark="edge", rgb1="0.2 0.3 0.4", rgb2="0.1 0.2 0.3", markrgb="0.8 0.8 0.8",
                  width="300", height="300")
    ET.SubElement(asset, "material", name="groundplane", texture="groundplane",
                  texuniform="true", texrepeat="5 5", reflectance="0.2")
    worldbody = ET.SubElement(root, "worldbody")
    ET.SubElement(worldbody, "light", pos="0 0 3", dir="0 0 -1", type="directional")
    floor = ET.SubElement(worldbody, "geom", name="floor", size="0 0 0.05", type="plane",
                          material="groundplane", contype="1", conaffinity="1")
    if world is not None:
        from sim.mujoco.world_scene import add_world_to_scene

        add_world_to_scene(worldbody, floor, world)
    # trackcom in the world body follows the whole model's centre of mass: the robot.
    target = (0.0, 0.0, 0.6 * height)
    eye = (1.1 * height, -1.7 * height, 0.75 * height)
    ET.SubElement(worldbody, "camera", name="track", mode="trackcom", pos=fmt(*eye),
                  xyaxes=_look_at(eye, target))
    return _to_string(root)


def _joint_qpos(model: mujoco.MjModel, name: str) -> int:
    return int(model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)])


def standing_qpos(model: mujoco.MjModel, pose: Mapping[str, float]) -> npt.NDArray[np.float64]:
    """qpos with the joints at ``pose`` [rad] (missing joints 0), torso upright at x = y = 0
    and its height [m] chosen so the lowest sole point touches z = 0."""
    data = mujoco.MjData(model)
    qpos = np.zeros(model.nq)
    qpos[3] = 1.0
    for name, q in pose.items():
        qpos[_joint_qpos(model, name)] = q
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    lowest = min(float(geom_points(model, data, g)[:, 2].min())
                 for foot in foot_geoms(model) for g in foot)
    qpos[2] = -lowest
    return qpos


def build_mjcf(robot: RobotConfig, *, timestep: float | None = None,
               world: World | None = None) -> Mjcf:
    """Robot and scene MJCF for ``robot``; timestep [s] (default 0.002); ``world``: the
    scene's floor and bumps (``sim.mujoco.world``; None or ``World()``: the plain floor)."""
    dt = DEFAULT_TIMESTEP if timestep is None else timestep
    if not 0 < dt <= 0.01:
        raise ConfigError(f"MJCF: timestep must be in (0, 0.01] s, got {dt}")
    bare = _compile(robot_xml(robot, timestep=dt))
    fixed = {j.name: j.fixed_rad for j in robot.joints if j.fixed_rad is not None}
    home = standing_qpos(bare, {**robot.rest, **fixed})
    ctrl = home[bare.jnt_qposadr[bare.actuator_trnid[:, 0]]]
    return Mjcf(robot=robot_xml(robot, timestep=dt, home=home, ctrl=ctrl),
                scene=scene_xml(robot, world=world))
