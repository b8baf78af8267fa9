"""Independent finite-element checks (gmsh meshes, scikit-fem solvers) of the models in
:mod:`semianalytic`: the potential problem of Part I, the elastic spherical cavity of
Part II and the rod-oscillation problem of Part I, section 2.

``fem_check`` may import ``semianalytic``; never the reverse.
"""
