"""The import's interpolant for sampled curves (robot/motion/interp.py ``spline``,
robot/motion/kinks.py) against curves known in closed form: a cubic comes back exactly, a
smooth curve to O(h^4), a curve with kinks at known times has them found and put back; a
limit the frames stay inside is never crossed between them. And a glTF of keyframes
(CUBICSPLINE or STEP tracks) is not sampled: the import keeps the monotone cubic."""

from __future__ import annotations

import numpy as np
import pygltflib as gl
import pytest

from robot.motion.interp import smooth, spline
from robot.motion.kinks import kinks, sampled
from robot.previs.gltf_read import read_gltf

H = 1.0 / 30.0


def test_a_cubic_comes_back_exactly_at_uneven_samples() -> None:
    rng = np.random.default_rng(3)
    times = np.sort(np.r_[0.0, rng.uniform(0, 2, 9), 2.0])
    f = lambda t: 0.3 - 0.7 * t + 0.4 * t ** 2 - 0.15 * t ** 3  # noqa: E731
    t = np.linspace(0, 2, 777)
    assert np.abs(spline(times, f(times)[:, None], t)[:, 0] - f(t)).max() < 1e-12


def test_a_smooth_curve_is_recovered_where_the_monotone_cubic_flattens_its_peaks() -> None:
    """sin(2 pi 1.3 t) at 30 fps: the spline's error is O(h^4) (5/384 h^4 max|f''''| =
    2.7e-4 rad by de Boor's bound for the clamped spline)."""
    w = 2 * np.pi * 1.3
    times = np.arange(61) * H
    t = np.linspace(0, 2, 4001)
    v = np.sin(w * times)[:, None]
    err_spline = np.abs(spline(times, v, t)[:, 0] - np.sin(w * t)).max()
    err_monotone = np.abs(smooth(times, v, t)[:, 0] - np.sin(w * t)).max()
    assert err_spline < 5 / 384 * H ** 4 * w ** 4 * 1.1
    assert err_monotone > 10 * err_spline


def _lift(t: np.ndarray) -> np.ndarray:
    """max(0, sin) of a 0.8 s cycle plus a slow sway: kinks (velocity steps of 2 pi 0.5 /
    0.8 rad/s) where the sine crosses 0: t = 0.4 k."""
    return 0.5 * np.maximum(0.0, np.sin(2 * np.pi * t / 0.8)) + 0.1 * np.sin(2 * np.pi * t / 3.1)


def test_kinks_are_found_where_they_are_and_the_curve_comes_back() -> None:
    times = np.arange(115) * H + 0.013             # kinks between frames, not on them
    frames = _lift(times)
    found = [times[0] + pos * H for pos, _ in kinks(frames)]
    truth = [0.4 * k for k in range(1, 10)]
    assert len(found) == len(truth)
    assert np.abs(np.array(found) - truth).max() < 0.1 * H
    t = np.linspace(times[0], times[-1], 5001)
    ours = sampled(times, frames[:, None], t, lo=np.array([-1.0]), hi=np.array([1.0]))[:, 0]
    assert np.abs(ours - _lift(t)).max() < 0.003
    assert np.abs(spline(times, frames[:, None], t)[:, 0] - _lift(t)).max() > 0.01


def test_a_smooth_curve_has_no_kinks() -> None:
    times = np.arange(300) * H
    assert kinks(np.sin(2 * np.pi * 0.9 * times) + 0.2 * np.cos(2 * np.pi * 2.3 * times)) == []


def test_no_limit_is_crossed_that_the_frames_do_not_cross() -> None:
    """A step to the limit rings in any C2 spline; kept at the limit between frames inside
    it, and let past it where the frames themselves are past (the violation is reported)."""
    frames = np.array([0.0] * 8 + [1.0] * 8 + [1.4] * 3 + [1.0] * 8)
    times = np.arange(len(frames)) * H
    t = np.linspace(0, times[-1], 3000)
    raw = spline(times, frames[:, None], t)[:, 0]
    assert raw.max() > 1.4 + 1e-3 or raw.min() < -1e-3     # it rings
    kept = sampled(times, frames[:, None], t, lo=np.array([-0.5]), hi=np.array([1.0]))[:, 0]
    inside = t < times[15]
    assert kept[inside].max() <= 1.0 + 1e-12 and kept.min() >= -0.5
    assert kept.max() >= 1.4 - 1e-9                          # the frames past it: kept


def _gltf(path: str, interpolation: str) -> None:
    """One bone, one rotation track of three keys about x (keys at 0, 0.5, 1 s)."""
    times = np.array([0.0, 0.5, 1.0], dtype="<f4")
    quats = np.array([[np.sin(a / 2), 0, 0, np.cos(a / 2)] for a in (0.0, 0.8, 0.2)],
                     dtype="<f4")
    if interpolation == "CUBICSPLINE":            # in-tangent, value, out-tangent per key
        quats = np.repeat(quats, 3, axis=0)
        quats[0::3] = 0.0
        quats[2::3] = 0.0
    blob = times.tobytes() + quats.tobytes()
    doc = gl.GLTF2(
        nodes=[gl.Node(name="root", children=[1]), gl.Node(name="bone", translation=[0, 1, 0])],
        skins=[gl.Skin(joints=[0, 1])],
        buffers=[gl.Buffer(byteLength=len(blob))],
        bufferViews=[gl.BufferView(buffer=0, byteOffset=0, byteLength=times.nbytes),
                     gl.BufferView(buffer=0, byteOffset=times.nbytes, byteLength=quats.nbytes)],
        accessors=[gl.Accessor(bufferView=0, componentType=5126, count=3, type="SCALAR",
                               min=[0.0], max=[1.0]),
                   gl.Accessor(bufferView=1, componentType=5126, count=len(quats), type="VEC4")],
        animations=[gl.Animation(samplers=[gl.AnimationSampler(input=0, output=1,
                                                               interpolation=interpolation)],
                                 channels=[gl.AnimationChannel(sampler=0, target=gl.AnimationChannelTarget(
                                     node=1, path="rotation"))])])
    doc.set_binary_blob(blob)
    doc.save_binary(path)


@pytest.mark.parametrize(("interpolation", "is_sampled"),
                         [("LINEAR", True), ("STEP", False), ("CUBICSPLINE", False)])
def test_a_gltf_of_keyframes_is_not_sampled(tmp_path, interpolation: str, is_sampled: bool) -> None:
    path = str(tmp_path / "k.glb")
    _gltf(path, interpolation)
    assert read_gltf(path).sampled is is_sampled
