"""The ``bal_*`` gait parameters: the balance feedback's gains (robot/balance/stage.py;
used only with an IMU and balance on), as (default, lo, hi, unit, meaning);
robot.config.params makes them parameters of the "balance feedback" group."""

from __future__ import annotations

BALANCE_GAINS: dict[str, tuple[float, float, float, str, str]] = {
    "bal_ankle_pd": (0.05, 0.0, 1.0, "s", "ankle pitch/roll per torso "
                     "tilt rate [rad per rad/s] (gyro damping)"),
    "bal_hip_pd": (0.0, 0.0, 1.0, "s", "hip pitch/roll per torso tilt "
                   "rate [rad per rad/s] (gyro damping)"),
    "bal_ankle_pp": (0.0, 0.0, 3.0, "-", "ankle pitch/roll per rad of "
                     "torso tilt from upright"),
    "bal_lean_i": (1.0, 0.0, 5.0, "1/s", "rate at which the pelvis learns "
                   "the lean a slope needs [rad/s per rad of tilt]"),
    "bal_lean_max": (0.15, 0.0, 0.4, "rad", "largest learned lean (pelvis "
                     "roll/pitch relative to the feet)"),
    "bal_step_gain": (0.0, 0.0, 3.0, "-", "capture step: the swinging "
                      "foot lands this many times the capture-point error at "
                      "touchdown further toward the fall (1: the capture step; 0: "
                      "no stepping)"),
    "bal_step_max": (0.04, 0.0, 0.1, "m", "largest capture step (each "
                     "way forward, back and outward) from the gait's own footstep"),
    "bal_step_dead": (0.02, 0.0, 0.1, "m", "capture-point error ignored "
                      "by stepping and tempo (the walk's own unlearned rocking)"),
    "bal_brace_xi": (0.0, 0.0, 0.2, "m", "capture-point error at which "
                     "the swinging foot is put down and the gait holds still (a "
                     "mostly forward error waits for the foot to land; 0: never)"),
    "bal_brace_s": (0.5, 0.0, 3.0, "s", "the gait holds still this long "
                    "after the error was last that large"),
    "bal_brace_max_s": (0.0, 0.0, 3.0, "s", "a brace that has held this "
                        "long and still sees the error is given up: the gait steps "
                        "(capture step, no brace or hold) until the error is back "
                        "under bal_brace_xi (0: the brace holds as long as the "
                        "error does)"),
    "bal_hold_xi": (0.0, 0.0, 0.2, "m", "lateral capture-point error "
                    "toward the foot that lifts next at which the gait holds in "
                    "double support (a loaded foot is not lifted; 0: never)"),
    "bal_tempo_max": (0.5, 0.0, 3.0, "-", "largest phase speed-up when a "
                      "capture step is out of reach (0.5: the swing ends up to 1.5 x "
                      "sooner)"),
    "bal_swing_level": (0.0, 0.0, 1.5, "-", "the swinging foot turned "
                        "with this share of the torso's unexpected tilt (1: kept "
                        "level with the ground, so it lands where the step was "
                        "planned)"),
    "bal_kin_xi": (0.0, 0.0, 1.0, "-", "share of the capture-point "
                   "error taken from the legs' kinematics (joint angles and IMU "
                   "tilt: where the body stands over its feet) rather than from "
                   "the torso's tilt alone (0: tilt only)"),
    "bal_learn_cycles": (4.0, 0.0, 50.0, "cycle", "time constant of the "
                         "learned gait rhythm the stepping ignores (0: none)"),
    "bal_heading_p": (0.5, 0.0, 2.0, "1/step", "turn trim per rad of "
                      "heading error [rad/step per rad]"),
    "bal_heading_i": (0.2, 0.0, 2.0, "1/(step s)", "turn trim per rad*s "
                      "of heading error"),
    "bal_turn_max": (0.2, 0.0, 0.5, "rad/step", "largest turn trim the "
                     "heading loop may add"),
    "bal_stop_close": (1.0, 0.0, 1.0, "-", "a stop finishes the swing in "
                       "progress and brings the other foot beside it in the next one "
                       "(1; the envelope holds while both feet are down), or shrinks the "
                       "stride over ramp_cycles as without balance (0)"),
    "bal_stride_turn": (0.0, -2.0, 2.0, "-", "5-DoF legs (no hip yaw): "
                        "the heading loop's turn trim steers by step length x "
                        "this; 1 where `--set turn=0.05` turns the robot left, -1 "
                        "where it turns it right, 0: not steered"),
}
