"""The citation page's BibTeX, written from ``CITATION.cff`` when the site is built (a Sphinx extension).

``docs/changelog.md`` includes ``CHANGELOG.md`` and ``docs/citation.md`` shows ``CITATION.cff``
itself; this writes the BibTeX entries of the same file (the software and its preferred citation,
the paper) into ``docs/_build/generated/citation.bib``, which the citation page includes: nothing
of either file is copied by hand.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[2]
BIB = ROOT / "docs" / "_build" / "generated" / "citation.bib"


def _authors(people: list[dict[str, str]]) -> str:
    names = []
    for p in people:
        if "family-names" in p:
            names.append(f"{p['family-names']}, {p.get('given-names', '')}".strip(", "))
        else:
            names.append("{" + p["name"] + "}")
    return " and ".join(names)


def bibtex(cff: dict[str, Any]) -> str:
    """The BibTeX entries of a CITATION.cff: the preferred citation first, then the software.

    >>> print(bibtex({"title": "t", "version": "1", "authors": [{"name": "Us"}]}))
    @software{grazing,
      title = {t},
      author = {{Us}},
      version = {1},
    }
    """
    entries = []
    pref = cff.get("preferred-citation")
    if pref:
        fields = {"title": pref.get("title"), "author": _authors(pref.get("authors", [])),
                  "journal": pref.get("journal"), "volume": pref.get("volume"),
                  "number": pref.get("issue"), "year": pref.get("year"), "doi": pref.get("doi")}  # fmt: skip
        if pref.get("start"):
            fields["pages"] = f"{pref['start']}--{pref['end']}" if pref.get("end") else pref["start"]
        family = pref["authors"][0].get("family-names", "paper").lower()
        entries.append((f"{family}{pref.get('year', '')}", "article", fields))
    fields = {"title": cff.get("title"), "author": _authors(cff.get("authors", [])),
              "version": cff.get("version"), "url": cff.get("repository-code") or cff.get("url")}  # fmt: skip
    entries.append(("grazing", "software", fields))
    out = []
    for key, kind, fields in entries:
        body = "".join(f"  {k} = {{{v}}},\n" for k, v in fields.items() if v not in (None, ""))
        out.append(f"@{kind}{{{key},\n{body}}}")
    return "\n\n".join(out)


def write_bib(app: Any) -> None:
    BIB.parent.mkdir(parents=True, exist_ok=True)
    text = bibtex(yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))) + "\n"
    if not BIB.exists() or BIB.read_text() != text:
        BIB.write_text(text)


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", write_bib)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
