"""HiWonder/LewanSoul LX serial bus servos (robot/bus/lx/bus.py speaks their protocol).

The protocol has no model number: ``number`` is biped's own label (scan reports the robot
file's model). No gains: the firmware takes a position and a move time, nothing else (gain
set "lx" is empty). Positions 0..1000 cover 0..240 deg (0.24 deg a step): 1001 positions,
each 0.24 deg wide, so ``span_deg`` 240.24 gives exactly 1000 steps per 240 deg.
"""

from __future__ import annotations

from robot.servo.model import KGCM, ServoModel, per_60deg

LX, _RES, _SPAN = "lx", 1001, 240.24

MODELS: dict[str, ServoModel] = {m.name: m for m in (
    # LX-16A (LewanSoul spec sheet): 17 kg cm at 7.4 V (15 at 6.6 V), 0.16 s/60 deg at
    # 7.4 V (0.18 at 6 V), 52 g, 6-8.4 V.
    ServoModel("LX-16A", 16, LX, _RES, 17 * KGCM, per_60deg(0.16), 0.052, 7.4, _SPAN,
               gain_set=LX),
    # LX-224 / LX-224HV (HiWonder listings, not a datasheet page: an assumption until one is
    # at hand): 20 kg cm, 0.20 s/60 deg at 7.4 V (LX-224, 6-8.4 V) and 0.18 s/60 deg at
    # 11.1 V (LX-224HV, 9-12.6 V); about 60 g.
    ServoModel("LX-224", 224, LX, _RES, 20 * KGCM, per_60deg(0.20), 0.060, 7.4, _SPAN,
               gain_set=LX),
    ServoModel("LX-224HV", 2240, LX, _RES, 20 * KGCM, per_60deg(0.18), 0.060, 11.1, _SPAN,
               gain_set=LX),
)}
