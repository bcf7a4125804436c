"""matcad: one geometry spec → fabrication kit and acoustic prediction for MAT taxels (lengths in mm)."""

__version__ = "0.1.0"
