"""What the design page asks of the server besides builds: a taxel's or a board's prediction as plain data, the
spec as TOML and back, and a build's progress. Frequencies Hz, lengths mm, times s."""

from __future__ import annotations

import tomllib

from matcad.serve.common import Refused, spec_of


def _taxel_json(band, prediction) -> dict:
    """One taxel's row of the page: its band (unloaded and loaded, Hz; position mm), every model's f0 and
    validity, the chosen model, the uncertainty budget and the warnings."""
    return {**band.to_dict(), "band_hz": list(prediction.band_hz),
            "models": {k: {"f0_hz": m.f0_hz, "valid": m.valid} for k, m in prediction.models.items()},
            "budget": [{"source": b.source, "low_hz": b.low_hz, "high_hz": b.high_hz} for b in prediction.budget],
            "warnings": list(prediction.warnings)}


def predict_json(payload: dict) -> dict:
    """The prediction of the request's spec as plain data (Hz, mm). A board ([[taxel]] or [array]) is predicted as
    `matcad predict` predicts it (:func:`matcad.prediction.board.predict_board`: every taxel, its loaded band from
    the cap mechanics or its calibration, the conflicts); a single taxel by :func:`matcad.prediction.predict` with
    its unloaded band (no FElupe on every keystroke). ``"mechanics": false`` in the request predicts a board without
    its caps' rise under load (``rise_pending``: the page shows these bands at once and asks again for the rises,
    which take a FElupe run per cap not yet cached). The first taxel's numbers are also at the top level. A board's
    layout findings (``layout``: caps off the plate, on a fastener or too close, jets, ligaments, the mold's slots,
    crossing bores; :mod:`matcad.rules.board`, ~0.01 s) come with it, so that adding or moving a taxel is judged
    as it is typed, not at the build."""
    from matcad.prediction import predict, taxel_band
    from matcad.prediction.bands import summary
    from matcad.spec import is_array, spec_notes

    spec = spec_of(payload)
    mechanics = payload.get("mechanics", True)
    if not isinstance(mechanics, bool):
        raise Refused(422, f"mechanics {str(mechanics)[:40]!r} invalid, must be true or false", "mechanics")
    notes = spec_notes(spec, payload["spec"])
    layout = []
    if is_array(spec):
        from matcad.prediction.board import predict_board
        from matcad.rules import board as board_rules

        board = predict_board(spec, mechanics=mechanics)
        layout = [f.to_dict() for rule in board_rules.RULES for f in rule(spec) if f.level != "info"]
        bands, predictions = board.bands, [board.predictions[b.name] for b in board.bands]
        data = board.summary
    else:
        p = predict(spec)
        bands, predictions = [taxel_band(spec, mechanics=False, prediction=p)], [p]
        data = summary(spec, bands)
    rows = [_taxel_json(b, p) for b, p in zip(bands, predictions)]
    first = rows[0]
    return {"name": spec.name, "board": len(rows) > 1, "f0_hz": first["f0_hz"], "band_hz": first["band_hz"],
            "model": first["model"], "models": first["models"], "budget": first["budget"],
            "warnings": [w for row in rows for w in
                         ((f"{row['name']}: {w}" for w in row["warnings"]) if len(rows) > 1 else row["warnings"])],
            "notes": notes, "taxels": rows, "guard_hz": data["guard_hz"], "max_force_n": data["max_force_n"],
            "harmonics": data["harmonics"], "conflicts": data["conflicts"], "layout": layout,
            "rise_pending": is_array(spec) and not mechanics}


def spec_toml(payload: dict) -> dict:
    """The request's spec (validated first) as TOML text, written with the project's TOML writer."""
    import tomli_w

    spec = spec_of(payload)
    return {"name": spec.name, "toml": tomli_w.dumps(payload["spec"])}


def spec_from_toml(payload: dict) -> dict:
    """``{"toml": text}`` → ``{"spec": {...}}`` as TOML reads it (the page then predicts it, which validates it);
    a TOML syntax error is told with its line."""
    text = payload.get("toml")
    if not isinstance(text, str):
        raise Refused(422, 'the request must be {"toml": "..."}')
    try:
        return {"spec": tomllib.loads(text)}
    except tomllib.TOMLDecodeError as exc:
        raise Refused(422, f"not TOML: {exc}") from None
