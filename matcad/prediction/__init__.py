"""The prediction of a taxel or a board: the acoustics (:mod:`matcad.acoustics`) composed with the cap mechanics
(:mod:`matcad.mechanics`) and Eq. 5 calibrations. Frequencies Hz, forces N, lengths mm.

- :mod:`matcad.prediction.taxel` — one taxel: unloaded f0 and band, and f(F) at asked forces;
- :mod:`matcad.prediction.bands` — each taxel's unloaded and loaded band, a board's conflicts and its summary.

Each name is imported from its module when first asked for, so that one taxel's prediction does not load a
board's.
"""

import importlib

_HOMES = {"TaxelBand": "bands", "conflicts": "bands", "listening_bands": "bands", "summary": "bands",
          "taxel_band": "bands", "taxel_bands": "bands", "predict": "taxel"}
"""The module of :mod:`matcad.prediction` each exported name lives in."""

__all__ = ["TaxelBand", "conflicts", "listening_bands", "predict", "summary", "taxel_band", "taxel_bands"]


def __getattr__(name: str):
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
    globals()[name] = value
    return value
