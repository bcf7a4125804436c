"""Acoustic core: pure numpy, never imports a CAD kernel. Lengths in mm, frequencies in Hz."""
