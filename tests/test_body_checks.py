"""robot/body/checks.py on body trees built here: each refusal (one line naming the link
and what was found), each fix and its warning, and MuJoCo as the judge of what is
physical (it refuses the broken inertias and takes the fixed ones)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from robot.body.checks import DENSITY_RANGE, check_tree
from robot.body.tree import BodyTree, Hinge, Inertial, Link, Shape
from robot.errors import ConfigError

GOOD = Inertial(mass=0.1, com=(0.0, 0.0, -0.03), inertia=(4e-5, 5e-5, 6e-5, 1e-6, 0.0, 0.0))


def _tree(leg: Inertial | None, *, shapes: tuple[Shape, ...] = (),
          welded: Inertial | None = None) -> BodyTree:
    base = Link("base", -1, inertial=Inertial(0.5, (0, 0, 0), (1e-3,) * 3 + (0,) * 3))
    links = [base, Link("leg", 0, pos=(0, 0.05, 0), inertial=leg, shapes=shapes,
                        joint=Hinge("hip", (0.0, 1.0, 0.0)))]
    if welded is not None:
        links.append(Link("sensor", 1, pos=(0, 0, -0.1), inertial=welded))
    return BodyTree(tuple(links), source="test.urdf")


def _mujoco_takes(inert: Inertial) -> str:
    """'' when MuJoCo compiles a hinged body of ``inert``, else its error's first line."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="leg", mass=inert.mass, ipos=list(inert.com),
                                   fullinertia=[inert.inertia[k] for k in (0, 1, 2, 3, 4, 5)])
    body.add_joint(type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
    try:
        spec.compile()
    except ValueError as err:
        return str(err).splitlines()[0]
    return ""


def _refused(tree: BodyTree, *words: str, fix: bool = False) -> None:
    with pytest.raises(ConfigError) as err:
        check_tree(tree, fix=fix)
    text = str(err.value)
    assert "\n" not in text and text.startswith("test.urdf: link '"), text
    for w in words:
        assert w in text, (w, text)


def test_a_sound_tree_passes_untouched() -> None:
    tree = _tree(GOOD, welded=Inertial(0.0, (0, 0, 0), (0.0,) * 6))
    out, warnings = check_tree(tree)
    assert out == tree and warnings == [] and _mujoco_takes(GOOD) == ""


@pytest.mark.parametrize("mass", [-0.1, math.nan, math.inf])
def test_masses_that_are_not_physical(mass: float) -> None:
    bad = Inertial(mass, GOOD.com, GOOD.inertia)
    _refused(_tree(bad), "link 'leg'", f"mass {mass} kg", "give it a mass and inertia")
    _refused(_tree(bad), "no collision shape", fix=True)
    box = Shape(kind="box", pos=(0.0, 0.0, -0.04), size=(0.01, 0.015, 0.04))
    out, warnings = check_tree(_tree(bad, shapes=(box,)), fix=True)
    fixed = out.links[1].inertial
    assert fixed is not None
    assert fixed.mass == pytest.approx(1000.0 * 0.02 * 0.03 * 0.08, rel=1e-12)
    assert warnings == [f"test.urdf: link 'leg': mass {mass} kg: mass {mass:.4g} kg -> 0.048 kg, centre "
                        "of mass (0, 0, -0.04) m, inertia (2.92e-05, 2.72e-05, 5.2e-06, 0, 0, 0) kg "
                        "m^2 from its collision shapes at 1000 kg/m^3"]
    assert _mujoco_takes(fixed) == ""


def test_a_moving_link_carrying_no_mass() -> None:
    _refused(_tree(None), "link 'leg'", "moved by hinge 'hip', it and the links it carries have no mass")
    alone = BodyTree((Link("base", -1, inertial=Inertial(0.0, (0, 0, 0), (0.0,) * 6)),), source="test.urdf")
    _refused(alone, "link 'base'", "the root, it and the links it carries have no mass", "--fix-inertia")
    # a massless hinged link carrying a massive one is fine (MuJoCo agrees)
    tree = _tree(None, welded=GOOD)
    assert check_tree(tree) == (tree, [])
    hull = Shape(kind="hull", vertices=((0, 0, 0), (0.02, 0, 0), (0, 0.02, 0), (0, 0, 0.02)))
    out, warnings = check_tree(_tree(None, shapes=(hull,)), fix=True)
    fixed = out.links[1].inertial
    assert fixed is not None  # MuJoCo keeps meshes in float32:
    assert fixed.mass == pytest.approx(1000.0 * 0.02**3 / 6, rel=1e-6)
    np.testing.assert_allclose(fixed.com, (0.005, 0.005, 0.005), atol=1e-9)
    assert "mass none -> 0.001333 kg" in warnings[0]


def test_inertias_no_body_has() -> None:
    point = Inertial(0.1, (0, 0, 0), (0.0,) * 6)
    triangle = Inertial(0.1, (0, 0, 0), (1e-5, 1e-5, 5e-5, 0, 0, 0))
    negative = Inertial(0.1, (0, 0, 0), (-1e-5, -2e-5, -1e-5, 0, 0, 0))
    for bad in (point, triangle, negative):
        assert _mujoco_takes(bad) != ""
    _refused(_tree(point), "link 'leg'", "inertia not positive definite", "(0, 0, 0)")
    _refused(_tree(triangle), "break the triangle inequality", "1e-05 + 1e-05 < 5e-05",
             "--fix-inertia sets the moments to their mean")
    _refused(_tree(negative), "not positive definite", "(-2e-05, -1e-05, -1e-05)")
    out, warnings = check_tree(_tree(triangle), fix=True)
    assert out.links[1].inertial is not None
    assert out.links[1].inertial.inertia == pytest.approx((7e-5 / 3,) * 3 + (0.0,) * 3, abs=1e-20)
    assert "moments -> (2.333e-05, 2.333e-05, 2.333e-05) kg m^2, each set to their mean" in warnings[0]
    for bad in (point, negative):
        out, warnings = check_tree(_tree(bad), fix=True)
        fixed = out.links[1].inertial
        assert fixed is not None and _mujoco_takes(fixed) == ""
        radius = (3 * 0.1 / (4 * math.pi * 1000.0)) ** (1 / 3)  # a 0.1 kg sphere of water
        np.testing.assert_allclose(fixed.inertia[:3], (0.4 * 0.1 * radius**2,) * 3, rtol=1e-12)
        assert "a solid sphere's of its mass at 1000 kg/m^3" in warnings[0]


def _density(inert: Inertial) -> float:
    """Mass over the equivalent box's volume, from the moments by the box formula."""
    a, b, c = np.linalg.eigvalsh(inert.matrix())
    return inert.mass / math.sqrt((6 / inert.mass) ** 3 * (b + c - a) * (a + c - b) * (a + b - c))


@pytest.mark.parametrize(("factor", "end"), [(1e6, 0), (1e-6, 1)])
def test_inertias_wrong_by_orders_of_magnitude(factor: float, end: int) -> None:
    """kg mm^2 read as kg m^2 (x 1e6) and the other way round."""
    assert DENSITY_RANGE[0] < _density(GOOD) < DENSITY_RANGE[1]
    slipped = Inertial(GOOD.mass, GOOD.com, tuple(v * factor for v in GOOD.inertia))  # type: ignore[arg-type]
    assert _mujoco_takes(slipped) == ""  # MuJoCo would simulate it: only this check catches it
    _refused(_tree(slipped), "link 'leg'", "equivalent-inertia box has a density of",
             "outside the plausible 20-20000", "wrong unit")
    out, warnings = check_tree(_tree(slipped), fix=True)
    fixed = out.links[1].inertial
    assert fixed is not None
    assert _density(fixed) == pytest.approx(DENSITY_RANGE[end], rel=1e-9)
    ratio = fixed.inertia[0] / slipped.inertia[0]
    np.testing.assert_allclose(fixed.inertia, np.asarray(slipped.inertia) * ratio, rtol=1e-12)
    assert f"inertia scaled by {ratio:.4g}" in warnings[0]
    assert f"density {DENSITY_RANGE[end]:g}" in warnings[0]
