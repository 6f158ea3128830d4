"""What the emulator needs to build one servo (``ServoSpec``)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ServoSpec:
    """What the emulator needs to build one servo.

    servo_id: bus id; model: key of ``servo_models.MODELS``; zero_ticks: initial present
    position [ticks]; min_ticks/max_ticks: position limits [ticks]; baud: [bit/s];
    return_delay: Return Delay Time register [raw steps] (0: a chain already set up).
    """

    servo_id: int
    model: str
    zero_ticks: int
    min_ticks: int
    max_ticks: int
    baud: int
    return_delay: int = 0
    #: a dual-axis servo's case (its two axes share one number; 0: a one-axis servo)
    case: int = 0
