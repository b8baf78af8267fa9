"""The per-user cache of coefficient tables A(P), B(P), C(P) (one idea: build once, reuse).

A table is stored as ``<key>.npz`` where the key is a content hash of

- the geometry (nose kind, diameter, nose length and every shape parameter),
- the numerical options (order, refinement, levels, depths, ...) and
- the code version (:data:`semianalytic.coefficients.table.TABLE_VERSION`, bumped when the
  numerics change),

so a changed nose, option or numerics never reads a stale table.  The folder is, in order:
an explicit ``cache_dir`` (the commands' ``--cache-dir``), ``$SEMIANALYTIC_CACHE_DIR``, or
the per-user cache folder of platformdirs (``~/.cache/semianalytic`` on Linux), sub-folder
``coefficients``.  Commands never write a cache into the working directory.  Files are
written atomically and carry their key and a checksum (:func:`semianalytic.io.write_cache_entry`);
a damaged, truncated, other-version or other-nose file is discarded with a warning and rebuilt.

Used alike by the ``run`` pipeline, the sweeps, the ``penetrate`` command and fem_check.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from semianalytic.native import CACHE_ENV, cache_root  # lives below the models (their compiled kernels use it)

__all__ = ["CACHE_ENV", "cache_root", "table_dir", "table_key", "cached_coefficient_table", "coefficients_for_case",
           "case_table_request", "case_table_key", "plate_table_key", "cached_plate_table"]


def table_dir(cache_dir: str | os.PathLike | None = None) -> Path:
    """The folder of the coefficient tables: ``cache_dir`` as given, else ``cache_root()/coefficients``."""
    return Path(cache_dir).expanduser() if cache_dir is not None else cache_root() / "coefficients"


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in sorted(obj.items())}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, float):
        return repr(obj)
    return obj


def table_key(nose, **options) -> str:
    """Content hash of the geometry, the numerical options and the code version (the cache key)."""
    from semianalytic.coefficients.table import TABLE_VERSION

    payload = json.dumps(
        {"nose": [nose.kind, nose.diameter, nose.length, _jsonable(nose.parameters)], "options": options,
         "version": TABLE_VERSION},
        sort_keys=True,
    )
    return hashlib.sha256(payload.encode()).hexdigest()[:20]


def cached_coefficient_table(nose, cache_dir: str | os.PathLike | None = None, **options):
    """:func:`semianalytic.coefficients.table.coefficient_table`, read from the cache when there,
    else built and stored (atomically) under :func:`table_key`.  Each entry carries its key and a
    checksum (:func:`read_table_entry`): a damaged or mismatched one is discarded with a warning
    and rebuilt."""
    from semianalytic.coefficients.table import coefficient_table

    key = table_key(nose, **{k: v for k, v in options.items() if k != 'progress'})
    path = table_dir(cache_dir) / f"{key}.npz"
    table = read_table_entry(path, key, nose)
    if table is not None:
        return table
    table = coefficient_table(nose, **options)
    write_table_entry(path, key, table)
    return table


def plate_table_key(nose, thickness: float, **options) -> str:
    """Cache key of a plate table: as :func:`table_key`, with the plate's thickness H [m] and
    the plate code's version (:data:`semianalytic.coefficients.plate.PLATE_VERSION`)."""
    from semianalytic.coefficients.plate import PLATE_VERSION

    if options.get("depths") is not None:
        options = {**options, "depths": [float(P) for P in options["depths"]]}
    payload = json.dumps(
        {"nose": [nose.kind, nose.diameter, nose.length, _jsonable(nose.parameters)], "thickness": repr(float(thickness)),
         "options": _jsonable(options), "plate_version": PLATE_VERSION},
        sort_keys=True,
    )
    return "plate-" + hashlib.sha256(payload.encode()).hexdigest()[:20]


def cached_plate_table(nose, thickness: float, cache_dir: str | os.PathLike | None = None, **options):
    """:func:`semianalytic.coefficients.plate.plate_coefficient_table` of a nose in a plate of
    thickness H [m], read from the cache when there, else built and stored (atomically) under
    :func:`plate_table_key`.  ``reading`` is applied after reading (it is not part of the key)."""
    import io
    import warnings

    from semianalytic.coefficients.plate import PlateCoefficientTable, plate_coefficient_table
    from semianalytic.io import CacheWarning, read_cache_entry, write_cache_entry

    reading = options.pop("reading", "body")
    key = plate_table_key(nose, thickness, **{k: v for k, v in options.items() if k != "progress"})
    path = table_dir(cache_dir) / f"{key}.npz"
    payload = read_cache_entry(path, key, "plate-table cache")  # key and checksum verified
    if payload is not None:
        try:
            return PlateCoefficientTable.from_npz(io.BytesIO(payload)).with_reading(reading)
        except Exception as exc:  # noqa: BLE001 - an unreadable entry is rebuilt, never trusted
            warnings.warn(f"plate-table cache: discarded the entry {path.name!r}: unreadable ({type(exc).__name__}); "
                          "it is rebuilt", CacheWarning, stacklevel=2)
    from semianalytic.progress import stages

    bar = stages(1, "plate table")  # seconds per table: a line in a log, a bar on a terminal
    bar.step(f"BEM plate table of the {nose.kind} nose, H = {thickness * 1e3:.4g} mm (built once, then cached)")
    try:
        table = plate_coefficient_table(nose, thickness, **options)
    finally:
        bar.close()
    try:
        write_cache_entry(path, key, table.to_npz_bytes(), thickness=float(thickness))
    except OSError:
        pass  # a cache that cannot be written: the table is rebuilt next time
    return table.with_reading(reading)


def read_table_entry(path: Path, key: str, nose=None):
    """The table stored in ``path`` under ``key``, or None (absent; or damaged, truncated, of
    another version or of another nose: then removed with a warning).  With ``nose``, the
    table's own nose (kind, diameter, nose length) must be that nose."""
    import io
    import math
    import warnings

    from semianalytic.coefficients.table import CoefficientTable
    from semianalytic.io import CacheWarning, read_cache_entry

    payload = read_cache_entry(path, key, "coefficient-table cache")
    if payload is None:
        return None
    why = None
    try:
        table = CoefficientTable.from_npz(io.BytesIO(payload))
    except Exception as exc:  # noqa: BLE001 - any unreadable entry is rebuilt, never trusted
        table, why = None, f"unreadable ({type(exc).__name__})"
    if table is not None and nose is not None and not (
            table.nose_kind == nose.kind and math.isclose(table.diameter, nose.diameter, rel_tol=1e-12)
            and math.isclose(table.nose_length, nose.length, rel_tol=1e-12, abs_tol=1e-300)):
        table, why = None, f"a table of another nose ({table.nose_kind}, diameter {table.diameter:g} m)"
    if table is None:
        warnings.warn(f"coefficient-table cache: discarded the entry {path.name!r}: {why}; it is rebuilt",
                      CacheWarning, stacklevel=2)
        try:
            path.unlink()
        except OSError:
            pass
    return table


def write_table_entry(path: Path, key: str, table) -> None:
    """Store ``table`` under ``key`` with its checksum (atomically; a read-only cache is skipped)."""
    from semianalytic.io import write_cache_entry

    try:
        write_cache_entry(path, key, table.to_npz_bytes(), nose=[table.nose_kind, table.diameter, table.nose_length])
    except OSError:
        pass  # a cache that cannot be written: the table is rebuilt next time


def coefficients_for_case(case, source: str = "bem", cache_dir=None, progress: bool = False, tolerance=None):
    """(coefficients, description, fallback) for a case.

    ``source="bem"``: the BEM table of the case's nose (cached on disk), in the B reading of
    ``[coefficients] reading`` (errata item 2a); ``"paper"``: the paper's quoted constants
    (:func:`semianalytic.penetration.curve.paper_coefficients`).  ``tolerance`` overrides
    ``[coefficients] tolerance`` (the table's relative interpolation error).  ``fallback`` is always False (kept in the
    tuple for the callers that print a fallback warning).
    """
    from semianalytic.errors import InputError

    psec = case.require("projectile")
    if source == "paper":
        from semianalytic.penetration.curve import paper_coefficients  # the models: only for the paper's constants

        return paper_coefficients(psec), "the paper's quoted deep-penetration Abar, Bbar, Cbar (constant in P)", False
    if source != "bem":
        raise InputError("coefficients", f"must be 'bem' or 'paper'; got {source!r}")
    cs = case.coefficients
    tolerance = cs.tolerance if tolerance is None else tolerance
    nose, kwargs = case_table_request(case, tolerance)
    refinement = kwargs.get("refinement")
    table = cached_coefficient_table(nose, cache_dir, progress=progress, **kwargs).with_reading(cs.reading)
    ref = f"refinement {refinement:g}" if refinement is not None else "default refinement"
    grid = f"{cs.depths} fixed depths" if cs.depths is not None else f"{len(table.depth)} adaptive knots, tolerance {tolerance:g}"
    desc = (
        f"BEM table (order {case.bem.order}, {ref}, {grid}, to the deep limit; B reading '{cs.reading}')"
    )
    return table, desc, False


def case_table_request(case, tolerance=None):
    """(nose, options) of the case's coefficient table: what :func:`cached_coefficient_table`
    is called with (the one place that reads them from the case; ``case_table_key`` hashes them)."""
    from semianalytic.geometry import nose_from_section

    cs = case.coefficients
    kwargs = dict(order=case.bem.order, max_depth_nose_lengths=cs.max_depth_nose_lengths)
    if cs.depths is not None:  # a fixed grid
        kwargs["n_depths"] = cs.depths
    else:
        kwargs["tolerance"] = cs.tolerance if tolerance is None else tolerance
    refinement = getattr(case.bem, "refinement", None)
    if refinement is not None:  # else the table's own default
        kwargs["refinement"] = refinement
    return nose_from_section(case.require("projectile")), kwargs


def case_table_key(case, tolerance=None) -> str:
    """The cache key (:func:`table_key`) of the case's coefficient table and its B reading:
    every nose parameter and numerical option, whatever the nose kind (the sweeps' resource key)."""
    nose, kwargs = case_table_request(case, tolerance)
    return f"{table_key(nose, **kwargs)}:{case.coefficients.reading}"


def override_coefficients(case, *, contact: str | None = None, tolerance=None):
    """The case with ``[coefficients] contact`` / ``tolerance`` replaced by command-line flags
    (``--contact``, ``--tolerance``; None keeps the case's value)."""
    import dataclasses

    from semianalytic.sections.coefficients import parse_tolerance

    updates = {}
    if contact is not None:
        updates["contact"] = contact
    if tolerance is not None:
        updates["tolerance"] = parse_tolerance(tolerance)
    if not updates:
        return case
    return dataclasses.replace(case, coefficients=case.coefficients.model_copy(update=updates))
