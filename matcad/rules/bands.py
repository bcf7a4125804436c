"""Rules on a board's bands: one microphone must tell every taxel apart (matcad.prediction.bands).

Each taxel's loaded band (its predicted band plus the rise up to ``mechanics.max_force_n``) must stay the loop's
guard (:func:`matcad.prediction.bands.guard_hz`) away from every other taxel's: otherwise the tracker cannot say
which taxel it hears (an error). The 2nd and 3rd harmonics of a loaded band may lie in another band (issue 24): the
board tracker predicts them from the taxel's own track and discounts the frames on them
(:func:`matcad.loop.board.discount_harmonics`), so such a band costs only the frames where the two coincide — a
warning naming them, no longer an error that sends the band above the harmonic.
Single-taxel specs have nothing to separate and skip these rules (so their check never runs the cap mechanics).
"""

from __future__ import annotations

from matcad.rules.finding import Finding

FIX = ("move the taxels apart in frequency (`matcad design --taxels N --band LO HI` allocates disjoint bands), "
       "lower mechanics.max_force_n, or narrow the bands: a calipered sheet (plate.thickness_measured) and a "
       "recorded [reference] taxel shrink the model uncertainty")

HARMONIC_NOTE = ("tracked around: the board tracker predicts this harmonic from the taxel's own tone and leaves out "
                 "the frames on it, so the other taxel has no reading where its tone meets the harmonic")


def band_separation(spec) -> list[Finding]:
    """Errors for every pair of loaded bands closer than the guard, warnings for every 2f/3f of one taxel's loaded
    band within the guard of another's band; an info line with each taxel's bands (Hz)."""
    from matcad.listening import guard_hz
    from matcad.prediction.bands import conflicts, taxel_bands
    from matcad.spec import is_array

    if not is_array(spec):
        return []
    bands = taxel_bands(spec)
    guard = guard_hz(spec.microphone.sample_rate_hz)
    out = [Finding("bands.overlap", "error", round(c.gap_hz, 1), round(guard, 1), c.describe(), FIX)
           if c.harmonic == 1 else
           Finding("bands.harmonic", "warning", round(c.gap_hz, 1), round(guard, 1), c.describe(), HARMONIC_NOTE)
           for c in conflicts(bands, guard)]
    listing = "; ".join(f"{b.name} {b.loaded_hz[0]:.0f}-{b.loaded_hz[1]:.0f} Hz" for b in bands)
    out.append(Finding("bands.allocation", "info", {b.name: [round(v) for v in b.loaded_hz] for b in bands},
                       round(guard, 1), f"loaded bands up to {spec.mechanics.max_force_n:g} N: {listing}"))
    return out


RULES = (band_separation,)
