"""The FEM check of the BEM coefficients from Python (`python -m fem_check verify --quick`).

An independent finite-element solution (gmsh, scikit-fem, P2 elements) of the potential problem
of Part I, eq. (7) around the Fig. 5 ogive at a depth of two nose lengths: A, B and C by FEM
and by the BEM, and their largest relative difference.
"""

from fem_check.api import verify

result = verify("cases/fig5_ogive.toml", [2.0], h=0.1, quick=True, quiet=True)
row = result["depths"][0]
for name in ("A", "B", "C"):
    print(f"{name}: BEM {row[name + '_bem']:.6g}, FEM {row[name + '_fem']:.6g}")
print(f"largest relative BEM-FEM difference: {result['max_rel_diff']:.1e}")
