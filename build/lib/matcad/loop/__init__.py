"""The recording loop: frequency from recordings (analyze), Eq. 5 calibration with uncertainty (calibrate),
and force from sound (sense). Frequencies Hz, forces N, volumes mm³."""


class LoopError(Exception):
    """The data cannot give a trustworthy answer (no tone, tone at a band edge, degenerate calibration):
    exit code 1 with the reason."""
