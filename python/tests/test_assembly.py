"""`cosdem.Assembly`: one DEM assembly driven from Python, against the closed forms of a
hexagonal lattice and against `cosdem rve`."""

from __future__ import annotations

import csv
import subprocess

import numpy as np
import pytest

import cosdem

KN, KS, KR = 6.7e7, 3.4e7, 25.0  # the default contact law (the paper's)
XX, YY, XY, YX, KX, KY = range(6)


def periodic_hexagon() -> dict:
    return {
        "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.2},
        "boundary": {"kind": "periodic"},
    }


def test_tangent_of_a_periodic_hexagonal_cell_has_the_closed_forms_ratios():
    """A compressed periodic hexagonal cell (every contact closed): the tangent is the
    lattice's closed form `rho/8 (3 k_n + k_s, k_n - k_s, k_n + 3 k_s, k_n - k_s)`, `rho/2
    k_r`, whose ratios do not depend on the contact density `rho`. The Rust tests match the
    entries to 1e-9 at the counted density; 1e-8 here leaves room for the ratio's rounding.
    Also checks the Voigt order the package documents."""
    a = cosdem.Assembly(periodic_hexagon())
    r = a.solve(np.diag([1 - 1e-3, 1 - 1e-3]))
    assert r.diagnostics["converged"]
    c = r.tangent
    assert c.shape == (6, 6)
    base = c[XX, YY]
    for name, got, want in [
        ("C_xxxx", c[XX, XX], (3 * KN + KS) / (KN - KS)),
        ("C_yyyy", c[YY, YY], (3 * KN + KS) / (KN - KS)),
        ("C_xyxy", c[XY, XY], (KN + 3 * KS) / (KN - KS)),
        ("C_yxyx", c[YX, YX], (KN + 3 * KS) / (KN - KS)),
        ("C_xyyx", c[XY, YX], 1.0),
        ("D_xx", c[KX, KX], 4 * KR / (KN - KS)),
    ]:
        assert got / base == pytest.approx(want, rel=1e-8), name
    # compression: negative, equal normal stresses; no shear or couple stress
    assert r.stress[0, 0] < 0 and r.stress[0, 0] == pytest.approx(r.stress[1, 1], rel=1e-9)
    assert abs(r.stress[0, 1]) < 1e-9 * abs(r.stress[0, 0]) and r.couple_stress.shape == (2,)
    np.testing.assert_array_equal(r.voigt[:2], np.diag(r.stress))


def test_a_python_loop_is_cosdem_rves_isotropic_path(fixture_job, tmp_path, cli):
    """`cosdem rve --path isotropic`, written as a Python loop of solve and commit, gives
    the CLI's stresses to the bit (its CSV writes shortest round-trip numbers)."""
    steps, inc = 3, 1e-4
    out = tmp_path / "rve"
    subprocess.run(
        [cli, "rve", fixture_job("dem-one-element"), "--path", "isotropic", "--steps", str(steps),
         "--increment", str(inc), "--out", out],
        check=True, capture_output=True,
    )
    with open(out / "rve.csv") as f:
        rows = list(csv.DictReader(f))
    a = cosdem.Assembly(cosdem.Job.from_toml(fixture_job("dem-one-element")))
    assert a.disc_count == 105 and a.area == pytest.approx(0.01, rel=1e-12)
    for k in range(steps + 1):
        d = inc * k
        r = a.solve([[1 - d, 0], [0, 1 - d]])
        a.commit()
        for i, name in enumerate(["s_xx", "s_yy", "s_xy", "s_yx", "m_x", "m_y"]):
            assert r.voigt[i] == float(rows[k][name]), (k, name)
        assert r.diagnostics["steps"] == int(rows[k]["dem_steps"])


def test_rollback_returns_to_the_committed_state():
    """A trial rolled back leaves no trace: the same trial again gives the same bits. A
    committed trial is the start of the next one (path dependence)."""
    a = cosdem.Assembly(periodic_hexagon())
    f1 = [[1 - 1e-3, 0], [0, 1 - 1e-3]]
    f2 = [[1 - 1e-3, 2e-3], [0, 1 - 1e-3]]
    first = a.solve(f2).voigt.copy()
    a.rollback()
    np.testing.assert_array_equal(a.solve(f2).voigt, first)
    a.rollback()
    a.solve(f1)
    a.commit()
    via = a.solve(f2).voigt
    assert via[XY] != 0 and via[XX] < 0
    positions, radii = a.particles()
    assert positions.shape == (a.disc_count, 2) and np.all(radii == 0.005)


def test_bad_input_is_named(fixture_job):
    with pytest.raises(cosdem.JobError, match=r"at key `packing`: unknown field `radiuss`"):
        cosdem.Assembly({"packing": {"kind": "hexagonal", "radiuss": 0.005, "side": 0.2}})
    with pytest.raises(cosdem.JobError, match=r"radius"):
        cosdem.Assembly({"packing": {"kind": "hexagonal", "radius": -0.005, "side": 0.2}})
    with pytest.raises(cosdem.JobError, match='kind = "dem"'):
        cosdem.Assembly(cosdem.Job.from_toml(fixture_job("elastic-panel")))
    a = cosdem.Assembly(periodic_hexagon())
    with pytest.raises(ValueError, match=r"`F_xy` is not finite: NaN"):
        a.solve([[1.0, float("nan")], [0.0, 1.0]])
    with pytest.raises(ValueError, match=r"`k_y` is not finite"):
        a.solve(np.eye(2), 0.0, [0.0, float("inf")])
    with pytest.raises(ValueError, match=r"not invertible: det\(F\) = -1"):
        a.solve([[-1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match=r"F must be 2x2"):
        a.solve(np.eye(3))
