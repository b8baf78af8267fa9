"""TOML blocks shared by the tests' inline cases (one place for the target most of them use)."""

# 6061-T651 aluminium, elastic-perfectly plastic (Part I, eq. (16)) with the paper's Y = 400 MPa
TARGET_6061_T651 = """[target]
density = "2710 kg/m^3"
[target.resistance]
model = "elastic-plastic"
yield_stress = "400 MPa"
youngs_modulus = "68.9 GPa"
poisson_ratio = 0.33
"""

# coarse BEM tables (order 4, 16 depths to 30 nose lengths): about 0.5 s per design on one core, for
# tests of engines and optimisers (the same tables on every path), not of the coefficients' accuracy
COARSE_TABLES = """[bem]
order = 4
refinement = 0.2
[coefficients]
depths = 16
max_depth_nose_lengths = 30.0
"""


def copy_case(tmp_path, name: str, edit=None, data: str = "piekutowski1999_ogive_6061T6511.csv"):
    """Copy ``cases/NAME`` (and its data CSV) into ``tmp_path``, applying ``edit(text) -> text``
    (which must change something: an edit that no longer matches fails loudly)."""
    import shutil
    from pathlib import Path

    cases = Path(__file__).resolve().parent.parent / "cases"
    text = (cases / name).read_text()
    if edit is not None:
        new = edit(text)
        assert new != text
        text = new
    (tmp_path / name).write_text(text)
    shutil.copy(cases / data, tmp_path / data)
    return tmp_path / name
