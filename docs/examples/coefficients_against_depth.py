"""Drag coefficients A, B, C against depth (Part I, Fig. 8).

The certified BEM table of the Fig. 5 ogive read at a few depths of the tip, as the bars of
Fig. 8: Abar = 4A/(pi d^2) is a length, Bbar and Cbar are numbers. At depth the paper prints
Abar = 1.0 mm, Bbar = 0.11, Cbar = 1.00.
"""

from semianalytic import api

case = api.load_case("cases/fig5_ogive.toml")
L_h = 11.8e-3  # nose length of the Fig. 5 ogive [m]
rows = api.coefficients_at(case, [0.25 * L_h, 0.5 * L_h, L_h, 2 * L_h, 20 * L_h])
print("P [mm]   Abar [mm]   Bbar     Cbar")
for P, A, B, C in zip(rows["depth_m"], rows["A_bar_m"], rows["B_bar"], rows["C_bar"]):
    print(f"{P * 1e3:6.2f}   {A * 1e3:9.4f}   {B:.4f}   {C:.4f}")
