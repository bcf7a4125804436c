"""Fast checks of the recording loop's decisions that a deliberate fault would break (issue 20): the listening band
of a single taxel's `analyze --spec`, the sense band and force from a calibration file, a crossing decided by the
two lines' levels, a hop onto where the second tone was, the voicing thresholds, and the temperature correction of
sense. Short synthetic recordings (matcad.loop.synth), a few seconds in all."""

from __future__ import annotations

import json
import math
import tomllib
import wave

import numpy as np
import pytest

from matcad.listening import CALIBRATED_MARGIN, PREDICTED_MARGIN, listening_band
from matcad.loop import synth
from matcad.loop.analyze import analyze
from matcad.acoustics.eq5fit import fit
from matcad.loop.sense import listening_band_hz, sense, sensing_law
from matcad.loop.voicing import Voicing
from tests.conftest import PAPER, run_cli

FS = synth.FS
BAND = (3900.0, 5600.0)


def _tone(freq_hz: float, seconds: float, seed: int = 0) -> np.ndarray:
    """A singing taxel at a steady ``freq_hz`` (Hz) over a pink-noise floor."""
    n = int(seconds * FS)
    return synth.taxel(np.full(n, freq_hz), FS, seed) + synth.coloured_noise(n, FS, seed + 1, 1.0, 0.01)


# --- the listening band --------------------------------------------------------------------------------------------

def test_listening_band_margins():
    """Each known band widened by its own factors, low edge below high edge (Hz)."""
    assert listening_band((4000.0, 5000.0), PREDICTED_MARGIN) == pytest.approx((3600.0, 6250.0))
    assert listening_band((4000.0, 5000.0), CALIBRATED_MARGIN) == pytest.approx((3200.0, 6250.0))


@pytest.mark.parametrize("fs", [44100.0, 96000.0])
def test_board_reads_a_tone_anywhere_in_its_loaded_band(fs):
    """A board taxel resting 5 Hz above its loaded band's low edge (inside its 95 % band) is read, beside a
    neighbour singing at its own band's top a guard below: the listening band is the loaded band widened by the edge
    zone (:func:`matcad.listening.loaded_listening_band`). Listening in the bare loaded band (the fault) drops those
    frames as the tone leaving its band."""
    from matcad.errors import LoopError
    from matcad.listening import guard_hz, loaded_listening_band
    from matcad.loop.board import analyze_board

    low = (1500.0, 1590.0)
    high = (low[1] + guard_hz(fs), low[1] + guard_hz(fs) + 90.0)
    assert loaded_listening_band(low, fs)[1] <= loaded_listening_band(high, fs)[0] + 1e-9  # they do not overlap
    n = int(3.0 * fs)
    x = (synth.taxel(np.full(n, low[1]), fs, 1) + synth.taxel(np.full(n, high[0] + 5.0), fs, 2)
         + synth.coloured_noise(n, fs, 3, 1.0, 0.01))
    a, b = (t.analysis for t in analyze_board([x], fs, [("a", loaded_listening_band(low, fs)),
                                                          ("b", loaded_listening_band(high, fs))]))
    assert abs(a.median_hz - low[1]) < 1.0 and a.voiced.mean() > 0.9
    assert abs(b.median_hz - (high[0] + 5.0)) < 1.0 and b.voiced.mean() > 0.9
    assert not any("edge" in w for w in (*a.warnings, *b.warnings))
    with pytest.raises(LoopError, match="hugs the band edge"):  # both at an edge of the bare loaded bands
        analyze_board([x], fs, [("a", low), ("b", high)])


def test_analyze_spec_listens_in_the_predicted_band_widened_and_finds_the_tone(tmp_path):
    """`analyze REC --spec` of a single taxel: the band the report states is the predicted unloaded band −10 %
    / +25 %, and a tone inside it is found."""
    from matcad import spec as spec_mod
    from matcad.prediction import predict

    lo, hi = predict(spec_mod.load(PAPER)).band_hz
    freq = 0.5 * (lo + hi)
    pcm = np.round(_tone(freq, 2.0) / 0.2 * 32767).astype("<i2")
    path = tmp_path / "tone.wav"
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(int(FS))
        w.writeframes(pcm.tobytes())
    code, out, err = run_cli("analyze", path, "--spec", PAPER, "--out", tmp_path / "a", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["band_hz"] == pytest.approx([0.9 * lo, 1.25 * hi])
    assert data["mean_hz"] == pytest.approx(freq, abs=2.0) and data["tone_fraction"] > 0.8
    assert json.loads((tmp_path / "a" / "report.json").read_text())["band_hz"] == data["band_hz"]


# --- sense: the band and the force from a calibration file ---------------------------------------------------------

@pytest.fixture(scope="module")
def calibration(tmp_path_factory):
    """(the Eq. 5 law read back from a calibration.toml, the TOML's table): Eq. 5 fitted to the paper's b and a
    (synth.EQ5) over 0-20 N, 1 Hz scatter, calibrated at 20 °C."""
    forces = np.tile(np.linspace(0.0, 20.0, 11), 2)
    freqs = synth.frequency_of_force(forces) + np.random.default_rng(5).normal(0.0, 1.0, len(forces))
    path = tmp_path_factory.mktemp("cal") / "calibration.toml"
    path.write_text(fit(forces, freqs, synth.K_MM3_HZ2, temperature_c=20.0).law.to_toml(), encoding="utf-8")
    from matcad.spec import load_calibration

    table = tomllib.loads(path.read_text())["calibration"]
    return sensing_law(load_calibration(path)), table


def test_sense_band_is_the_calibrated_range_widened(calibration):
    """Eq. 5 of the file's own v0, b, a at the ends of its force range, −20 % / +25 %: finite, in order."""
    cal, table = calibration

    def f(force):
        return math.sqrt(table["k_mm3_hz2"] / (table["v0_mm3"] - table["b"] * force - table["a"] * force**2))

    lo, hi = listening_band_hz(cal)
    assert np.isfinite([lo, hi]).all() and lo < hi
    assert (lo, hi) == pytest.approx((0.8 * f(0.0), 1.25 * f(20.0)))
    assert cal.frequency_range_hz() == pytest.approx((f(0.0), f(20.0)))


def test_sense_force_of_a_tone(calibration):
    """A steady tone at Eq. 5's pitch for 8 N, heard in the sense band, reads 8 N within its interval."""
    cal, _ = calibration
    analysis = analyze(_tone(float(synth.frequency_of_force(8.0)), 2.0), FS, listening_band_hz(cal))
    reading = sense(analysis, cal)
    assert reading.force_n == pytest.approx(8.0, abs=0.3)
    assert reading.force_interval_n[0] < 8.0 < reading.force_interval_n[1]
    force, _ = cal.force_with_interval(synth.frequency_of_force([2.0, 15.0]))
    assert force == pytest.approx([2.0, 15.0], abs=0.3)


def test_temperature_correction_direction(calibration):
    """Warmer air raises f by sqrt(T/T_cal) (kelvin): the factor that undoes it is sqrt(T_cal/T) < 1, and a tone
    heard 10 °C warmer reads the force it would have read at calibration — per frequency and through sense."""
    cal, _ = calibration
    assert cal.temperature_factor(30.0) == pytest.approx(math.sqrt(293.15 / 303.15), rel=1e-12)
    assert cal.temperature_factor(None) == 1.0
    heard = float(synth.frequency_of_force(8.0)) * math.sqrt(303.15 / 293.15)
    same, _ = cal.force_with_interval([float(synth.frequency_of_force(8.0))])
    fixed, _ = cal.force_with_interval([heard], temperature_c=30.0)
    assert fixed[0] == pytest.approx(same[0], abs=1e-9)
    reading = sense(analyze(_tone(heard, 2.0), FS, listening_band_hz(cal)), cal, 30.0)
    assert reading.force_n == pytest.approx(8.0, abs=0.3)


# --- crossing: decided by the lines' levels --------------------------------------------------------------------------

@pytest.mark.parametrize("taxel_db", [8.0, -8.0])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_touch_and_return_of_unequal_levels_is_decided_by_level(taxel_db, seed):
    """The taxel pressed up to a steady neighbour's pitch and released (synth.crossing_forces "touch"): the slopes
    before and after match either pairing equally, so the levels decide — the taxel 8 dB louder, or 8 dB weaker, than
    the neighbour. The track after the touch is the taxel's, not the neighbour's."""
    force, other = synth.crossing_forces("touch", 8.0, FS)
    t = np.arange(len(force)) / FS
    truth = synth.frequency_of_force(force)
    x = (synth.taxel(truth, FS, seed, amplitude=0.1 * 10 ** (min(taxel_db, 0.0) / 20))
         + synth.taxel(synth.frequency_of_force(other), FS, seed + 7, amplitude=0.1 * 10 ** (-max(taxel_db, 0.0) / 20),
                       gate=(t > 1.0).astype(float))
         + synth.coloured_noise(len(t), FS, seed + 3, 1.0, 0.01))
    a = analyze(x, FS, BAND)
    which = "louder" if taxel_db > 0 else "weaker"
    assert any("crossed" in w and f"dB {which} than the other" in w for w in a.warnings), a.warnings
    after = a.voiced & (a.times_s > 4.5)  # released: the taxel back at its 2 N pitch, the neighbour at 8 N
    err = np.abs(a.track_hz - truth[np.clip((a.times_s * FS).astype(int), 0, len(truth) - 1)])
    assert after.sum() > 50 and np.all(err[after] < 10.0)


def test_ridge_landing_where_the_second_tone_was_is_a_hop():
    """The ridge jumps 150 Hz onto a second tone seen for 30 frames before, and the taxel's own line is not seen
    after (a weaker taxel under a newcomer): a hop, said in a warning, and no frame after it is reported at the
    other tone's pitch; the frames before are the taxel's, unchanged. Per-frame lines at the analysis' bin spacing
    (matcad.listening), no recording."""
    from matcad.listening import ZERO_PAD, window_samples
    from matcad.loop.crossing import follow_taxel

    n, df = 60, FS / (ZERO_PAD * window_samples(FS))
    freqs = 3900.0 + df * np.arange(400)
    taxel, other = (freqs[round((hz - freqs[0]) / df)] for hz in (4450.0, 4600.0))
    frame = np.arange(n)
    track = np.where(frame < 40, taxel, other)
    seen = (frame >= 10) & (frame < 40)  # the second tone: 14 dB over its floor, 3 dB under the ridge
    other_bin = np.where(seen, round((other - freqs[0]) / df), round((5400.0 - freqs[0]) / df))
    identity = follow_taxel(frame * window_samples(FS) / 2 / FS, track, np.ones(n, dtype=int), other_bin,
                            np.where(seen, 14.0, 0.0), np.where(seen, -3.0, -30.0), np.full(n, 20.0), freqs)
    assert any("the ridge jumped" in w and "the taxel is kept on its line" in w for w in identity.warnings)
    assert not np.any((identity.state[40:] >= 1) & (np.abs(identity.track_hz[40:] - other) < 10.0))
    assert np.all(identity.state[:40] == 1) and np.all(identity.track_hz[:40] == taxel)


# --- voicing thresholds -----------------------------------------------------------------------------------------

def _voiced(excess_db, shift_db=0.0):
    """Voicing states of frames with these ridge excesses (dB) on one steady line, no harmonic sound, after 20 frames
    of nothing (no tone established)."""
    frames = [0.0] * 20 + list(excess_db) + [0.0] * 20
    voicing = Voicing()
    voicing.hear([False] * len(frames))
    for e in frames:
        voicing.step(e, 50.0, shift_db)
    return np.array(voicing.state[20:20 + len(excess_db)])


def test_weak_threshold_is_8_db_over_the_floor():
    """A new weak tone: 8 steady frames (~0.37 s) voice at 8.5 dB over the floor, not at 7.5 dB, nor at 8.5 dB
    when the clutter raises the thresholds by 1 dB."""
    assert _voiced([8.5] * 8).all()
    assert not _voiced([7.5] * 8).any()
    assert not _voiced([8.5] * 8, shift_db=1.0).any()
    assert not _voiced([8.5] * 7).any()


def test_strong_threshold_is_15_db_over_the_floor():
    """Two frames are enough when one stands 15.5 dB over the floor; at 14.5 dB they are not."""
    assert _voiced([15.5, 9.0]).all()
    assert not _voiced([14.5, 9.0]).any()


def test_a_band_narrower_than_the_tracker_needs_is_widened_about_its_centre():
    """:func:`matcad.listening.trackable`: a band under BAND_BINS + 1 bins (a tightly anchored taxel's) grows about
    its centre to exactly that width; a wider one is left as it is (Hz)."""
    from matcad.listening import BAND_BINS, ZERO_PAD, trackable, window_samples

    for fs in (44100.0, 96000.0):
        need = (BAND_BINS + 1) * fs / (ZERO_PAD * window_samples(fs))
        low, high = trackable((4600.0, 4630.0), fs)
        assert high - low == pytest.approx(need) and (low + high) / 2 == pytest.approx(4615.0)
        assert trackable((4000.0, 4000.0 + 2 * need), fs) == (4000.0, 4000.0 + 2 * need)
