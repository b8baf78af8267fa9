"""The perforation step of a ``run``: when the case's target has a ``thickness`` or
``[[target.layers]]``, V_r against V_s through :func:`semianalytic.commands.perforate.evaluate.evaluate_case`
with Part IV's V_cr as vertical lines, measured points as markers and the figure's data as CSV."""

from __future__ import annotations

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, register


def _applies(case: Case) -> bool:
    t = case.target
    return case.impact is not None and t is not None and (t.thickness is not None or bool(t.layers))


def _preflight(case: Case, run: RunSection) -> None:
    from semianalytic.commands.perforate.evaluate import load_perforation_data

    if not _applies(case):
        raise InputError("target.thickness", "missing: the perforation analysis needs a plate ('thickness') or [[target.layers]]")
    load_perforation_data(case)  # a missing or malformed data file: exit 2 before anything is computed


def _run(ctx: Context) -> None:
    from semianalytic.commands.perforate.evaluate import evaluate_case
    from semianalytic.commands.perforate.report import error_rows, figure_csv, perforation_figure

    try:
        res = evaluate_case(ctx.case, cache_dir=ctx.cache_dir)
    except InputError as exc:  # no velocity perforates: the curve without a ballistic limit
        if exc.field != "impact.striking_velocities":
            raise
        res = evaluate_case(ctx.case, cache_dir=ctx.cache_dir, ballistic=False)
        ctx.doc.note(f"No ballistic limit: {exc.message}")
    doc = ctx.doc
    doc.heading("Perforation (Part I, eq. (11) through the plate; Part IV)")
    doc.para(f"Target {res['thickness_m'] * 1e3:.4g} mm in {len(res['layers'])} layer(s); back face "
             f"`{res['back_face']}`, failure `{res['failure']}`. Coefficients: {res['coefficients']}.")
    if res["ballistic_limit_m_s"] is not None:
        if res.get("ballistic_limit_bound") == "lower":
            doc.para(f"Ballistic limit: above {res['ballistic_limit_m_s']:.1f} m/s (a lower bound: "
                     f"{res.get('ballistic_limit_reason', '')}).")
        else:
            doc.para(f"Ballistic limit (the command's own search on eq. (11)): {res['ballistic_limit_m_s']:.1f} m/s "
                     f"(error estimate {res['ballistic_limit_error_m_s']:.2g} m/s); failure mode "
                     f"{res.get('failure_mode')}.")
    f = lambda v, s=1.0: "-" if v is None else f"{v * s:.1f}"  # noqa: E731
    doc.table(["V_s [m/s]", "perforated", "V_r [m/s]", "depth [mm]", "exit time [us]"],
              [[f"{U:.0f}", str(p), f(v), f(d, 1e3), f(t, 1e6)] for U, p, v, d, t in zip(
                  res["striking_velocity_m_s"], res["perforated"], res["residual_velocity_m_s"], res["depth_m"],
                  res["exit_time_s"])], caption="Residual velocity per striking velocity.")
    rows = error_rows(res)
    if rows:
        doc.table(["predictor", "mean abs. error of V_bl [m/s]", "mean abs. error of V_r [m/s]"], rows,
                  caption="Against the measured residual velocities.")
    ctx.figure("perforation_residual_velocity", perforation_figure(res),
               "Residual velocity against striking velocity; vertical lines: the bisection's ballistic limit and "
               "Part IV's V_cr; markers: data.")
    rel = f"{ctx.run.figures_dir.rstrip('/')}/perforation_residual_velocity.csv"
    ctx.out.write_text(rel, figure_csv(res), field="run.figures_dir")
    doc.para(f"The figure's data: `{rel}`.")
    ctx.results["perforation"] = res


register(Step("perforation", "Perforation", ("projectile", "target", "impact"), ("semianalytic.perforation.model",),
              _applies, _preflight, _run))
