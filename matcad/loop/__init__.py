"""The recording loop: frequency from recordings (analyze), Eq. 5 calibration with uncertainty (calibrate),
and force from sound (sense). Frequencies Hz, forces N, volumes mm³.

Recordings in (``wav``) → spectra and the floor (``spectrum``) → combs removed (``combs``, ``harmonic``) → ridge
(``ridge``) → voicing (``voicing``) → segments (``segments``) → the result (``analysis``, via ``crossing``), wired
by ``tracker`` and driven by ``analyze``; a board of taxels (``board``); Eq. 5 fitted (``calibrate``) and read
back as force (``sense``); what it writes (``outputs``, ``plots``) and prints live (``live``). Where it listens:
:mod:`matcad.listening`. When the data cannot give a trustworthy answer it raises :class:`matcad.errors.LoopError`
(exit code 1)."""

