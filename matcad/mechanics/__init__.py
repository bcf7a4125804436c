"""Cap mechanics: the cast silicone end cap pressed by a flat plate, large strain, nearly incompressible.

``section`` (the cap's axisymmetric cross-section, pure numpy), ``material`` (hyperelastic presets from
:mod:`matcad.materials`), ``solver`` (FElupe, imported lazily: the force/volume curve), ``frequency`` (f(F) from the
deformed cavity through the acoustic ladder); ``plate`` (the neck plate bent as a beam by a pressed taxel, closed
form). Lengths mm, forces N, moduli MPa, volumes mm³.
"""
