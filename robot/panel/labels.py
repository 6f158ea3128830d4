"""What the panel calls each gait parameter, in words (the paper's symbol shows beside it,
``robot.config.params.SPECS`` gives the one-line meaning and range), and the "simple" view's set.

Kept with the panel (rather than in SPECS) because only the page shows them; a test checks
that every parameter has a label.
"""

from __future__ import annotations

LABELS: dict[str, str] = {
    "fps": "Animation frame rate", "vM": "Walking pace", "phi": "Pelvis bob rhythm",
    "omegaB": "Pelvis sway", "omegaC": "Chest sway", "k": "Spine rhythm",
    "Hosc": "Hip swing", "Hhgt": "Hip height", "Hpos": "Hip forward",
    "Sosc": "Shoulder swing", "Shgt": "Shoulder height", "Spos": "Shoulder forward",
    "delta_f": "Foot clearance", "Fhgt_R": "Foot height, right", "Fhgt_L": "Foot height, left",
    "Fpos_R": "Foot forward, right", "Fpos_L": "Foot forward, left",
    "Slgt_R": "Stride, right", "Slgt_L": "Stride, left",
    "Abnc_R": "Arm bounce, right", "Abnc_L": "Arm bounce, left",
    "omega_ra": "Arm swing, right", "omega_la": "Arm swing, left",
    "Apos_R": "Hand forward, right", "Apos_L": "Hand forward, left",
    "Ahgt_R": "Hand height, right", "Ahgt_L": "Hand height, left",
    "Aosc_R": "Hand wobble, right", "Aosc_L": "Hand wobble, left",
    "speed": "Speed", "turn": "Turn", "side_step": "Side step",
    "rig_leg": "Rig leg length", "stance": "Crouch (standing height)",
    "sway": "Weight shift", "sway_phase": "Weight shift timing", "foot_spread": "Feet apart",
    "torso_lean": "Lean forward", "spine_gain": "Torso pitch from the spine",
    "toe_gain": "Toe tilt in the swing", "arm_scale": "Arm motion scale",
    "ramp_cycles": "Start and stop smoothness",
    "stairs_rise": "Stairs: step height", "stairs_count": "Stairs: number of steps",
    "stairs_tread": "Stairs: tread depth", "stairs_x0": "Stairs: distance to the first step",
    "stairs_landing": "Stairs: landing depth", "stairs_margin": "Stairs: room ahead of the ankle",
    "stairs_margin_back": "Stairs: room behind the ankle",
    "stairs_odometry": "Stairs: step length actually made",
    "stairs_learn": "Stairs: learn how short steps land",
    "stairs_slow": "Stairs: slow down long steps", "stairs_reach": "Stairs: largest step change",
    "stairs_close": "Stairs: close up at a riser",
    "bal_ankle_pd": "Ankle damping", "bal_hip_pd": "Hip damping",
    "bal_ankle_pp": "Ankle stiffness", "bal_lean_i": "Slope learning",
    "bal_lean_max": "Largest learned lean", "bal_step_gain": "Step toward a fall",
    "bal_step_max": "Largest catch step", "bal_step_dead": "Ignore small wobbles",
    "bal_brace_xi": "Put the foot down at", "bal_brace_s": "Stand still for",
    "bal_brace_max_s": "Give up bracing after",
    "bal_hold_xi": "Don't lift a loaded foot", "bal_tempo_max": "Largest hurry",
    "bal_swing_level": "Keep the swinging foot level", "bal_kin_xi": "Capture point from the legs",
    "bal_learn_cycles": "Learn the walk's rhythm",
    "bal_heading_p": "Heading hold",
    "bal_heading_i": "Heading hold, slow part", "bal_turn_max": "Largest heading trim",
    "bal_stride_turn": "Heading hold by step length (no hip yaw)",
    "bal_stop_close": "Stop: finish the step",
}

#: The simple view: steer, foot height, stride, crouch (and the presets above them).
SIMPLE: tuple[str, ...] = ("speed", "turn", "side_step", "Fhgt_R", "Fhgt_L", "Slgt_R",
                           "Slgt_L", "stance")
