"""The prediction of a taxel or a board: the acoustics (:mod:`matcad.acoustics`) composed with the cap mechanics
(:mod:`matcad.mechanics`) and Eq. 5 calibrations. Frequencies Hz, forces N, lengths mm.

- :mod:`matcad.prediction.taxel` — one taxel: unloaded f0 and band, and f(F) at asked forces;
- :mod:`matcad.prediction.bands` — each taxel's unloaded and loaded band, a board's conflicts and its summary.
"""

from matcad.prediction.bands import TaxelBand, conflicts, listening_bands, summary, taxel_band, taxel_bands
from matcad.prediction.taxel import predict

__all__ = ["TaxelBand", "conflicts", "listening_bands", "predict", "summary", "taxel_band", "taxel_bands"]
