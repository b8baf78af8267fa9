"""Part IV ballistic limits of the Table 3 shots.

The theoretical V_cr of Part IV, eq. (5) with the three resistances R(1), R(2), R(3) and the
empirical V_cr of eqs. (7)-(9) beside the measured ballistic limits, one row per shot.
"""

from semianalytic import api

result = api.ballistic_limit(api.load_case("cases/part4_table3.toml"))
frame = result.to_frame()
columns = [c for c in ("name", "measured_V_m_s", "V_R1_m_s", "V_R2_m_s", "V_R3_m_s") if c in frame.columns]
print(frame[columns].round(0).to_string(index=False))
