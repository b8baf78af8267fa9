"""No silent non-convergence (issue 26, item 4): every iterative solve of eq. (11) returns its
status or raises; frozen means frozen; models raise ModelError, which the CLI dispatcher turns
into exit status 2 with one line."""

from __future__ import annotations

import dataclasses
import sys
import types

import numpy as np
import pytest

from semianalytic.coefficients import ConstantCoefficients
from semianalytic.errors import ConvergenceError, InputError, ModelError
from semianalytic.penetration.motion import (
    ConstantCoefficientSolution,
    RootResult,
    SeparatedProfile,
    depth_profile,
    final_depth,
)

COEF = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, 7.11e-3)
M, RHO, RT = 0.0134, 2710.0, 1.1e9


def test_root_status_reports_convergence_and_the_stop_slope():
    U = np.array([200.0, 900.0, 1500.0])
    prof = depth_profile(COEF, M, RHO, RT, U.max())
    res = prof.stop(U)
    assert isinstance(res, RootResult) and res.success and res.converged.all() and res.iterations <= 5
    s = [ConstantCoefficientSolution(COEF.A(0), COEF.B(0), COEF.C(0), M, RHO, RT, u) for u in U]
    np.testing.assert_allclose(res.x, [x.final_depth for x in s], rtol=1e-11)
    # -dw/dP at the stop = 2 |du/dt| at u = 0 = 2 C R_t / (m + rho A) (eq. (11)): the time at the stop uses it
    np.testing.assert_allclose(res.rate, [2.0 * x.deceleration0 for x in s], rtol=1e-10)


def test_a_root_that_cannot_converge_says_so():
    prof = depth_profile(COEF, M, RHO, RT, 1000.0)
    broken = dataclasses.replace(prof, _G=prof._G * np.nan)  # a profile the Newton passes cannot solve on
    res = broken.stop(np.array([500.0, 800.0]))
    assert not res.success and not res.converged.any() and res.iterations == 50
    with pytest.raises(ConvergenceError, match="did not converge in 50 Newton passes"):
        broken.final_depth(np.array([500.0]))


class _Leaky:
    """Coefficients whose drag vanishes beyond a depth: the projectile never stops (R_t > 0 still
    stops it, so this one has no strength term either): the integration in P must say so."""

    diameter = 7.11e-3

    def A(self, P):
        return np.zeros_like(np.asarray(P, float))

    def B(self, P):
        return np.where(np.asarray(P, float) < 0.01, 1e-6, 0.0)

    def C(self, P):
        return np.zeros_like(np.asarray(P, float))

    def deep_limit(self):
        return 0.0, 1e-6, 1e-6


def test_an_integration_that_never_reaches_the_stop_raises():
    with pytest.raises(ConvergenceError, match="did not reach"):
        final_depth(_Leaky(), M, RHO, RT, np.array([500.0]))


def test_model_errors_are_value_errors_with_a_field():
    with pytest.raises(ModelError, match="mass must be positive"):
        final_depth(COEF, -1.0, RHO, RT, 300.0)
    e = ModelError("bad\nthing")
    assert isinstance(e, ValueError) and not isinstance(e, InputError) and str(e) == "model: bad\\nthing"


def test_separated_profile_is_frozen_and_caches_outside_the_instance():
    names = {f.name for f in dataclasses.fields(SeparatedProfile)}
    assert names == {"wetted", "rtol"}  # no mutable cache among its fields
    prof = SeparatedProfile(wetted=object(), rtol=1e-10)
    with pytest.raises(dataclasses.FrozenInstanceError):
        prof.rtol = 1e-8  # type: ignore[misc]
    assert not hasattr(prof, "__dict__") or "_runs" not in vars(prof)


def test_bem_non_finite_solve_is_a_model_error():
    from semianalytic.bem.solve import raise_non_finite

    ps = types.SimpleNamespace(label="ogive nose")
    with pytest.raises(ModelError) as info:
        raise_non_finite(ps, 1e-3)
    assert not isinstance(info.value, InputError)
    assert info.value.field == "projectile" and "non-finite potential" in info.value.message


def test_cli_turns_a_model_error_into_exit_2_and_one_line(capsys, monkeypatch):
    from semianalytic.cli import dispatch

    mod = types.ModuleType("fake_model_command")
    mod.add_arguments = lambda parser: None

    def run(args):
        raise ConvergenceError("eq. (11) in P: the final depth did not converge in 50 Newton passes for 1 velocities")

    mod.run = run
    monkeypatch.setitem(sys.modules, "fake_model_command", mod)
    rc = dispatch("prog", {"fake": ("fake_model_command", "a model that fails")}, ["fake"])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.strip().splitlines() == ["error: model: eq. (11) in P: the final depth did not converge in 50 Newton "
                                        "passes for 1 velocities"]
