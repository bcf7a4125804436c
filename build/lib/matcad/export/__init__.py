"""Exporters: DXF/SVG for laser parts (ezdxf, plain SVG), STL/STEP for solids (build123d)."""
