"""report.md and report.html: one Markdown text rendered from the report data, and that same text as a page.

The Markdown (:func:`matcad.report.markdown.sections` plus the pictures and any report section this module does
not know, rendered generically) is the single source; the HTML is the Markdown through cmark-gfm (GitHub's
CommonMark reference implementation, with its table extension) in a self-contained page — inline style, images as
relative files beside it, no script, no network — so the two cannot drift.
"""

from __future__ import annotations

import html

from matcad.report.markdown import cell, part_anchor, sections

KNOWN_KEYS = frozenset({"matcad_version", "name", "spec", "as_built", "prediction", "findings", "verdict", "bom",
                        "meshes", "files", "figures", "casting", "fabrication", "bands", "taxels", "sheets",
                        "print_job"})
"""Report keys rendered by :func:`matcad.report.markdown.sections` or as pictures; every other key is rendered
generically (a list as a numbered list, a list of tables as a table, a table as key: value lines)."""
STYLE = """
body { font-family: system-ui, sans-serif; max-width: 68rem; margin: 2rem auto; padding: 0 1rem; color: #1a1a1a;
       line-height: 1.45; }
table { border-collapse: collapse; margin: 0.5rem 0 1rem; font-size: 0.9rem; }
th, td { border: 1px solid #c8c8c8; padding: 0.2rem 0.5rem; vertical-align: top; }
th { background: #eef2f7; }
img { max-width: 100%; border: 1px solid #e0e0e0; background: white; }
img[src$=".svg"] { width: 40rem; }
code { font-size: 0.85rem; }
h2 { border-bottom: 1px solid #ddd; margin-top: 2rem; }
.picture:target h3 { background: #fff3c4; }
@page { size: A4; margin: 12mm 12mm 14mm; }
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 9.5pt; line-height: 1.3; }
  h1 { font-size: 16pt; margin: 0 0 0.4rem; }
  h2 { font-size: 12.5pt; margin-top: 0.9rem; }
  h3 { font-size: 10.5pt; margin: 0.5rem 0 0.2rem; }
  h1, h2, h3 { break-after: avoid; page-break-after: avoid; break-inside: avoid; }
  p:has(+ table, + ul, + ol) { break-after: avoid; page-break-after: avoid; }
  .picture, img, tr, pre { break-inside: avoid; page-break-inside: avoid; }
  .picture { display: inline-block; vertical-align: top; width: 49%; margin: 0 0 0.3rem; }
  .picture img, img { max-height: 88mm; max-width: 100%; width: auto; border: none; }
  table { font-size: 8pt; margin: 0.3rem 0 0.6rem; }
  th, td { padding: 0.05rem 0.3rem; }
  a { color: inherit; text-decoration: none; }
}
"""
"""The page's look on screen and, under ``@media print``, on paper (A4): headings never end a page (they stay with
the table or picture that follows: ``break-after: avoid``), nor does a line that introduces a table or a list
("Trim:"), a picture and its caption are never split (``break-inside: avoid``) and two pictures share a row."""


def _pictures(r: dict) -> list[str]:
    """The pictures, each with its caption in one ``picture`` block (kept together on paper); a part's first
    picture carries the part's anchor (``#part-NAME``: the findings link to it)."""
    lines, seen = ["## Pictures", ""], set()
    for fig in r.get("figures", ()):
        anchor = ""
        if fig["part"] not in seen:
            seen.add(fig["part"])
            anchor = f' id="{part_anchor(fig["part"])}"'
        lines += [f'<div class="picture"{anchor}>', "", f"### {fig['caption']}", "",
                  f"![{fig['caption']}]({fig['file']})", "", "</div>", ""]
    return lines + [""] if seen else []


def _title(key: str) -> str:
    return key.replace("_", " ").capitalize()


def _generic(key: str, value) -> list[str]:
    """A report section this module does not know, as Markdown."""
    lines = [f"## {_title(key)}", ""]
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        cols = list(dict.fromkeys(k for v in value for k in v))
        lines += ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
        lines += ["| " + " | ".join(cell(v.get(c, "")) for c in cols) + " |" for v in value]
    elif isinstance(value, list):
        lines += [f"{i}. {cell(v)}" for i, v in enumerate(value, 1)]
    elif isinstance(value, dict):
        lines += [f"- {_title(k)}: {cell(v)}" for k, v in value.items()]
    else:
        lines.append(cell(value))
    return lines + [""]


def render_markdown(r: dict) -> str:
    """The report ``r`` as Markdown: its known sections (:func:`matcad.report.markdown.sections`) with the
    pictures after their title block and every unknown report key appended as its own section."""
    head, sep, rest = sections(r).partition("\n## ")
    lines = [head.rstrip("\n"), ""] + _pictures(r)
    text = "\n".join(lines) + (sep.lstrip("\n") + rest if sep else "")
    extra = [line for key, value in r.items() if key not in KNOWN_KEYS for line in _generic(key, value)]
    return text.rstrip("\n") + "\n" + ("\n" + "\n".join(extra).rstrip("\n") + "\n" if extra else "")


def render_html(markdown_text: str, title: str) -> str:
    """``markdown_text`` as one self-contained HTML page (CommonMark + GFM tables, column alignment as style
    attributes; inline HTML kept for anchors). cmark-gfm is C: a report is imported and rendered in ~1 ms."""
    import cmarkgfm
    from cmarkgfm.cmark import Options

    body = cmarkgfm.markdown_to_html_with_extensions(
        markdown_text, options=Options.CMARK_OPT_UNSAFE | Options.CMARK_OPT_TABLE_PREFER_STYLE_ATTRIBUTES,
        extensions=["table"])
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src 'self' data: file:; "
            "style-src 'unsafe-inline'\">\n"
            f"<title>{html.escape(title)}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n{body}</body>\n</html>\n")
