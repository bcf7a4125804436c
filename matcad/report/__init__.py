"""A build's report: report.json, report.md and report.html from one set of data.

- :mod:`~matcad.report.data`: the data (as built, bill of materials, casting, manifest) — :func:`make_report`;
- :mod:`~matcad.report.fabrication`: the fabrication plan (sheets to caliper, seal, fits, ordered steps);
- :mod:`~matcad.report.markdown`: the known sections as Markdown;
- :mod:`~matcad.report.page`: that Markdown with the pictures and any other section, and the same text as a page;
- :mod:`~matcad.report.files`: the files written — :func:`write_report`, :data:`REPORT_FILES`,
  :data:`KIT_ARCHIVE`.
"""

from matcad.report.data import make_report
from matcad.report.files import KIT_ARCHIVE, REPORT_FILES, write_report

__all__ = ["KIT_ARCHIVE", "REPORT_FILES", "make_report", "write_report"]
