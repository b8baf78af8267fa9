"""Tables a user reads or loads elsewhere, from the results of ``penetrate`` and ``run``
(they compute nothing):

- :func:`depth_csv`: ``--csv FILE``, one row per case, striking velocity and model, the units
  in the header;
- :func:`shot_table`: the per-shot table ``penetrate`` prints whenever the case has measured
  shots: predicted against measured depth, the relative error and, with ``--posterior``,
  whether the measured depth lies inside the 90 % predictive interval.
"""

from __future__ import annotations

import csv
import io
import math

__all__ = ["CSV_HEADER", "MODELS", "depth_rows", "depth_csv", "shot_table", "check_csv_target"]

# model name -> (depth key, time key or None) of the results of `penetrate` (evaluate_case) and
# of `run` (results.json "penetration"): lists over the striking velocities, SI units
MODELS = {
    "rigid": ("depth_rigid_m", "time_rigid_s"),
    "quasi_rigid": ("depth_quasi_rigid_m", "time_quasi_rigid_s"),
    "elastic": ("depth_elastic_m", "stop_time_elastic_s"),
    "elastic_exact_rod": ("depth_elastic_exact_rod_m", "stop_time_elastic_exact_rod_s"),
    "forrestal": ("depth_forrestal_m", None),
    "chen_li": ("depth_chen_li_m", None),
    "eroding": ("depth_eroding_m", None),
    "regime_aware": ("depth_m", None),
}
CSV_HEADER = ["case", "striking_velocity [m/s]", "model", "depth [m]", "time [s]", "regime", "valid"]


def _num(x) -> str:
    """A CSV cell: the number in full precision, empty when not finite (or absent)."""
    if x is None:
        return ""
    x = float(x)
    return repr(x) if math.isfinite(x) else ""


def depth_rows(result: dict, case_name: str) -> list[list[str]]:
    """Rows of :data:`CSV_HEADER` for one case's results (models the results lack are left out)."""
    U = list(result.get("striking_velocity_m_s", []))  # lists (penetrate) or arrays (run's results)
    valid = result.get("valid") or {}
    regime = list(result.get("regime", [""] * len(U)))
    rows = []
    for i, u in enumerate(U):
        for model, (dkey, tkey) in MODELS.items():
            if dkey not in result:
                continue
            t = result[tkey][i] if tkey and tkey in result else None
            ok = valid.get(model)
            rows.append([case_name, _num(u), model, _num(result[dkey][i]), _num(t), str(regime[i]),
                         "" if ok is None else str(bool(ok[i])).lower()])
    return rows


def depth_csv(results: list[tuple[str, dict]]) -> str:
    """The CSV text of ``--csv``: ``results`` is ``[(case name, results dict), ...]``."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_HEADER)
    for name, res in results:
        w.writerows(depth_rows(res, name))
    return buf.getvalue()


def check_csv_target(path: str, force: bool, inputs=()) -> None:
    """Refuse ``--csv FILE`` before any work: an existing file without ``--force``, a folder,
    one of the command's input files, a FIFO or device (issue 40), an existing file that this
    tool did not write (its first line is not :data:`CSV_HEADER`), or a folder that cannot be
    written."""
    import os
    from pathlib import Path

    from semianalytic.errors import InputError
    from semianalytic.io import check_file_target

    p = Path(path)
    if p.is_dir():
        raise InputError("--csv", f"{path!r} is a folder; expected a file name such as depths.csv")
    check_file_target(p, "--csv", inputs)
    if p.exists() and not force:
        raise InputError("--csv", f"{path!r} exists; pass --force to overwrite it")
    if p.exists():
        try:
            with p.open("rb") as fh:
                first = fh.readline(4096).decode("utf-8", "replace").strip()
        except OSError as exc:
            raise InputError("--csv", f"cannot read {path!r}: {exc.strerror}") from None
        if next(csv.reader([first]), None) != CSV_HEADER:
            raise InputError("--csv", f"{path!r} exists and was not written by this tool (its first line is not "
                                      "the depth table's header): --force replaces only the tool's own CSV files")
    parent = p.absolute().parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        raise InputError("--csv", f"cannot write {path!r}: {str(parent)!r} is not a writable folder")


def shot_table(rows: list[dict], model: str, intervals: dict | None = None) -> list[str]:
    """Lines of the per-shot table of ``penetrate`` for one model.

    ``rows``: the shots of ``result["validation"]["shots"]`` (measured and predicted depths in
    m); ``intervals``: optional ``{"0.05": [...], "0.95": [...]}`` at the shots' velocities (the
    90 % predictive interval of the posterior), else the column says ``-``.
    """
    lines = [f"  per shot (the shots of the statistics above), model {model}: error = (predicted - measured) / measured; "
             + ("inside = measured depth inside the 90 % predictive interval" if intervals else
                "inside: needs --posterior (90 % predictive interval)"),
             f"    {'shot':<10} {'U_s [m/s]':>9} {'predicted [mm]':>14} {'measured [mm]':>13} {'error [%]':>9} "
             f"{'90 % interval [mm]':>18} {'inside':>6}"]
    for k, r in enumerate(rows):
        pred, meas = r.get(model), r["measured_m"]
        err = (pred - meas) / meas * 100 if pred is not None and math.isfinite(pred) else math.nan
        if intervals:
            lo, hi = intervals["0.05"][k], intervals["0.95"][k]
            span = f"{lo * 1e3:.1f} - {hi * 1e3:.1f}" if lo is not None and hi is not None else "-"
            inside = "-" if lo is None or hi is None else ("yes" if lo <= meas <= hi else "no")
        else:
            span, inside = "-", "-"
        lines.append(f"    {str(r['shot']):<10} {r['velocity_m_s']:9.0f} {_mm(pred):>14} {_mm(meas):>13} "
                     f"{'nan' if not math.isfinite(err) else f'{err:+.1f}':>9} {span:>18} {inside:>6}")
    return lines


def _mm(x) -> str:
    return "nan" if x is None or not math.isfinite(x) else f"{x * 1e3:.1f}"
