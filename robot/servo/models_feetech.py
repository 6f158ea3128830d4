"""Feetech models: STS (magnetic encoder, 4096 steps, little-endian table) and SCS (SCSCL:
potentiometer, 1024 steps, big-endian table).

Model numbers are the two bytes at address 3-4 ("servo main / sub version") read in the
family's byte order, as feetech-servo-sdk's ping reports them with PacketHandler(0) (STS) or
PacketHandler(1) (SCS). Sources are named per entry; where no Feetech page at hand prints a
number the entry says so (and ``number_verified`` is False).
"""

from __future__ import annotations

from types import MappingProxyType

from robot.servo.model import KGCM, RPM, ServoModel, per_60deg

STS, SCS = "feetech_sts", "feetech_scs"
#: Feetech STS3215: P coefficient (21) 32, D coefficient (22) 32, I coefficient (23) 0 (the
#: servo's EPROM as shipped; LeRobot's Feetech bus notes "Default is 32" when it lowers P).
_STS_FACTORY = MappingProxyType({"p_coefficient": 32, "d_coefficient": 32, "i_coefficient": 0})
#: Feetech SCS15 manual v1.02, memory table: P (21) 15, D (22) 0, I (23) 0.
_SCS_FACTORY = MappingProxyType({"p_coefficient": 15, "d_coefficient": 0, "i_coefficient": 0})

MODELS: dict[str, ServoModel] = {m.name: m for m in (
    # STS3215 (7.4 V): 19.5 kg cm = 1.91 N m, 0.222 s/60 deg; 55 g; 777 (= 3 * 256 + 9).
    ServoModel("STS3215", 777, STS, 4096, 1.91, per_60deg(0.222), 0.055, 7.4,
               gain_set=STS, factory_gains=_STS_FACTORY),
    # STS3215 at 12 V (the C018 / C047 build, 1:345): 30 kg cm, 0.222 s/60 deg (45 rpm) at
    # 12 V, as Feetech's data is quoted by Robonine's test ("Testing of Feetech STS3215
    # Servomotor", 2025); it reports the same model number 777 as the 7.4 V build
    # (LeRobot's Feetech table has one STS3215 entry, used for both). Mass: the 7.4 V
    # build's (same case). Rhoban/bam identified it (params/feetech_sts3215_12V).
    ServoModel("STS3215-12V", 777, STS, 4096, 30 * KGCM, per_60deg(0.222), 0.055, 12.0,
               gain_set=STS, factory_gains=_STS_FACTORY),
    # STS3250 (12 V): 50 kg cm = 4.90 N m, 0.133 s/60 deg (Feetech datasheet, doc.
    # 6384135881578380868917773 A/0); 2825 (LeRobot's Feetech table); mass not in that
    # datasheet: 60 g estimated (the STS3215's 55 g case with a metal shell).
    # Gains: taken as the STS3215's (same STS firmware).
    ServoModel("STS3250", 2825, STS, 4096, 4.90, per_60deg(0.133), 0.060, 12.0,
               gain_set=STS, factory_gains=_STS_FACTORY),
    # STS3032: 4.5 kg cm = 0.44 N m, 0.1 s/60 deg at 6 V; 17 g. Model 1288 (= 5 * 256 + 8):
    # no Feetech page here prints it. Gains: taken as the STS3215's.
    ServoModel("STS3032", 1288, STS, 4096, 0.44, per_60deg(0.1), 0.017, 6.0,
               gain_set=STS, factory_gains=_STS_FACTORY, number_verified=False),
    # STS3046: no Feetech datasheet found. 30 kg cm and 0.222 s/60 deg at 12 V are the
    # STS3215-12V's (same STS case class), 60 g; model 3046 is a placeholder (no page
    # prints it; scan shows the robot file's model when it differs). Gains: the STS3215's.
    ServoModel("STS3046", 3046, STS, 4096, 30 * KGCM, per_60deg(0.222), 0.060, 12.0,
               gain_set=STS, factory_gains=_STS_FACTORY, number_verified=False),
    # SCS0009 (Waveshare's SC09 page for this Feetech servo): 2.3 kg cm at 6 V, 0.1 s/60
    # deg (100 rpm) at 6 V; 0..1023 over 300 deg; mass not printed: 14 g assumed (a micro
    # servo case); model 1284 (LeRobot's Feetech table, read big-endian).
    ServoModel("SCS0009", 1284, SCS, 1024, 2.3 * KGCM, 100 * RPM, 0.014, 6.0, 300.0,
               gain_set=SCS, factory_gains=_SCS_FACTORY),
    # SCS15 (Feetech FT-SCServo data sheet): 16.5 kg cm, 65 rpm at 7.4 V (15 kg cm, 55 rpm
    # at 6 V); potentiometer, 1024 positions over 215 deg (200 deg usable); 56 g.
    # Model number: no page at hand prints it (1295 = 5 * 256 + 15 is a placeholder).
    ServoModel("SCS15", 1295, SCS, 1024, 16.5 * KGCM, 65 * RPM, 0.056, 7.4, 215.0,
               gain_set=SCS, factory_gains=_SCS_FACTORY, number_verified=False),
    # SCS40: no Feetech datasheet found. 40 kg cm at 12 V is the torque class its name
    # states; 65 rpm, 215 deg over 1024 positions and the gains are the SCS15's; 70 g
    # assumed. Model 1320 (= 5 * 256 + 40) is a placeholder.
    ServoModel("SCS40", 1320, SCS, 1024, 40 * KGCM, 65 * RPM, 0.070, 12.0, 215.0,
               gain_set=SCS, factory_gains=_SCS_FACTORY, number_verified=False),
)}
