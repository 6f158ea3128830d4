"""The optional ``[imu]`` table of a robot file → ``ImuConfig`` (one-line errors naming the
file, the field and the valid range, like the rest of ``robot.config.robot_file``).

```toml
[imu]
kind = "sim"                 # "sim" (MuJoCo sensor) | "bno055" (UART) | a plugin's kind
mount_rpy_deg = [0, 0, 0]    # IMU frame in the torso frame: roll, pitch, yaw [deg]
noise = 1.0                  # sim: white-noise scale (1.0 = a BNO055's datasheet noise)
bias = 1.0                   # sim: constant-bias scale (1.0 = datasheet typical offsets)
latency_ms = 10.0            # sim: age of the sample a read returns [ms]
seed = 0                     # sim: noise and bias seed
fusion = true                # sim: report the fused quaternion (false: gyro+accel only)
# port = "/dev/serial0"      # bno055: the serial device (not for kind "sim")
```
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from robot.config.plugins import Registry
from robot.config.toml_io import Range, TomlValue, build, number, show, spec, table
from robot.errors import ConfigError

#: noise / bias: a scale of the BNO055 datasheet figures; 0 turns it off, 100 is absurd.
SCALE = Range(0.0, 100.0)
#: latency_ms: 0 to half a second (older data is useless to a balance loop).
LATENCY_MS = Range(0.0, 500.0, "ms")
#: seed: any unsigned 32-bit integer.
SEED = Range(0, 2**32 - 1)
#: mount_rpy_deg: each angle within half a turn.
MOUNT_DEG = Range(-180.0, 180.0, "deg")
#: Fields that only the simulated IMU uses.
SIM_ONLY = ("noise", "bias", "latency_ms", "seed", "fusion")
#: Fields that only serial devices use.
SERIAL_ONLY = ("port",)
#: The built-in serial device kinds.
SERIAL_KINDS = ("bno055",)
#: Entry-point group where IMU plugins are declared.
ENTRY_POINT_GROUP = "biped.imus"

#: IMU backends by kind: the built-in ones, the entry points of group ``biped.imus`` and the
#: ones registered at run time (``robot.imu.kinds.register_imu``). Each is a callable
#: ``(config: ImuConfig, *, bus) -> robot.imu.base.Imu``; the factory checks what it returns.
IMU_BACKENDS: Registry[Callable[..., object]] = Registry(ENTRY_POINT_GROUP, SERIAL_KINDS,
                                                       "imu.kind")


def imu_kinds() -> tuple[str, ...]:
    """Every IMU kind a robot file may name: plugins (registered or declared), then built-in."""
    return IMU_BACKENDS.kinds()


@dataclass(frozen=True)
class ImuConfig:
    """An IMU on the torso.

    kind: backend ("sim", "bno055" or a plugin, see ``robot.imu.factory``); port: serial
    device of a real IMU; mount_rpy_deg: roll, pitch, yaw of the IMU frame in the torso frame
    [deg] (URDF order: R = Rz(yaw) Ry(pitch) Rx(roll); all 0 when the chip's x/y/z are the
    torso's forward/left/up). Sim only: noise, bias: scales of the datasheet noise and
    offsets (docs/imu.md); latency_ms: age of the returned sample [ms]; seed: random seed;
    fusion: whether samples carry the fused quaternion (like a BNO055) or not.
    """

    kind: str
    port: str = "/dev/serial0"
    mount_rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    noise: float = field(default=1.0, metadata=spec(SCALE))
    bias: float = field(default=1.0, metadata=spec(SCALE))
    latency_ms: float = field(default=10.0, metadata=spec(LATENCY_MS))
    seed: int = field(default=0, metadata=spec(SEED))
    fusion: bool = True


def parse_imu(src: str, data: TomlValue) -> ImuConfig:
    """The ``[imu]`` table of robot file ``src``, validated."""
    tab = table(src, "imu", data)
    valid = [f for f in ImuConfig.__dataclass_fields__]
    unknown = sorted(set(tab) - set(valid))
    if unknown:
        raise ConfigError(f"{src}: imu.{unknown[0]}: unknown key; valid: {', '.join(valid)}")
    if "kind" not in tab:
        raise ConfigError(f"{src}: imu.kind: missing (expected one of "
                          f"{', '.join(imu_kinds())})")
    kind = tab["kind"]
    kinds = imu_kinds()
    if kind not in kinds:
        raise ConfigError(f"{src}: imu.kind: expected one of {', '.join(kinds)}, got "
                          f"{show(kind)}")
    if kind == "sim":
        wrong = [k for k in SERIAL_ONLY if k in tab]
        if wrong:
            raise ConfigError(f"{src}: imu.{wrong[0]}: not used by kind \"sim\" (the "
                              "simulated IMU reads MuJoCo); remove it")
    elif kind in SERIAL_KINDS:
        wrong = [k for k in SIM_ONLY if k in tab]
        if wrong:
            raise ConfigError(f"{src}: imu.{wrong[0]}: only for kind \"sim\" (a {kind} has "
                              f"its own noise and latency); remove it")
    mount = _mount(src, tab.get("mount_rpy_deg", [0.0, 0.0, 0.0]))
    fusion = tab.get("fusion", True)
    if not isinstance(fusion, bool):
        raise ConfigError(f"{src}: imu.fusion: expected true or false, got {show(fusion)}")
    flat = {k: v for k, v in tab.items() if k not in ("mount_rpy_deg", "fusion")}
    return build(ImuConfig, src, "imu", flat, overrides={"mount_rpy_deg": mount, "fusion": fusion})


def _mount(src: str, value: TomlValue) -> tuple[float, float, float]:
    path = "imu.mount_rpy_deg"
    if not isinstance(value, list) or len(value) != 3:
        raise ConfigError(f"{src}: {path}: expected [roll, pitch, yaw] in degrees, each in "
                          f"{MOUNT_DEG}, got {show(value)}")
    r, p, y = (number(src, f"{path}[{i}]", v, MOUNT_DEG) for i, v in enumerate(value))
    return (r, p, y)
