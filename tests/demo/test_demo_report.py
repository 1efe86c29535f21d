"""The report's page and Markdown: each score in its own named column, pictures full size behind
their thumbnails, a refused instruction said to be refused."""

from __future__ import annotations

import re
from pathlib import Path

from capnav.demo.report import SCORE_COLUMNS, Report, ReportItem, candidate_rows, verdict, write_html, write_markdown


def _items() -> list[ReportItem]:
    chosen = ReportItem("the pink armchair", "attribute", True, 6, "armchair", "ARMCHAIR, a pink armchair.", 0.376,
                        "Chose object 6 (...) because it has the highest verification score (1.11).",
                        reached=True, correct=True, right_object=True, view_png="images/01_view.png",
                        map_png="images/01_nav.png",
                        candidates=[{"id": 6, "label": "armchair", "similarity": 0.376, "verifier": 1.11, "final": 1.11,
                                     "why": "chosen", "chosen": True},
                                    {"id": 27, "label": "chair", "similarity": 0.36, "verifier": 0.41, "final": 0.41,
                                     "why": "ranked after the chosen object as a stand-in category", "chosen": False},
                                    {"id": 12, "label": "armchair", "similarity": 0.31, "verifier": 0.0, "final": 0.0,
                                     "why": "rejected: it is an armchair but colour pink vs observed light blue",
                                     "chosen": False},
                                    {"id": 9, "label": "armchair", "similarity": 0.2, "verifier": None, "final": 0.2,
                                     "why": "not verified (one before it was accepted)", "chosen": False}])
    refused = ReportItem("x" * 5000, "user", False, None, None, None, None, "instruction too long (5000 characters)",
                         rejected=True)
    return [chosen, refused]


def test_scores_sit_in_named_columns_on_one_scale_each() -> None:
    rows = candidate_rows(_items()[0])
    assert rows[0] == ("6 armchair", "0.38", "1.11", "1.11", "chosen")
    assert rows[1][1:4] == ("0.36", "0.41", "0.41")
    assert rows[2][2:4] == ("rejected", "-")  # a refusal is no score of 0
    assert rows[3][2:4] == ("-", "0.20")  # not judged: the final score is the similarity
    assert [n for n, _ in SCORE_COLUMNS] == ["similarity", "verifier", "final"]


def test_html_and_markdown(tmp_path: Path) -> None:
    rep = Report("CapNav demo: apartment 0", [("apartment seed", "0")], _items(), overview_png="images/map.png")
    write_html(rep, tmp_path / "r.html")
    write_markdown(rep, tmp_path / "r.md")
    page = (tmp_path / "r.html").read_text()
    for name, _ in SCORE_COLUMNS:
        assert f"<th>{name}</th>" in page and f"<dt>{name}</dt>" in page
    for pic in ("images/01_view.png", "images/01_nav.png", "images/map.png"):  # every picture is a link to itself
        assert re.search(rf"<a href='{pic}'[^>]*><img src='{pic}'", page), pic
    assert "max-height:360px" not in page and "(0.00)" not in page
    assert "rejected: instruction too long" in page and "x" * 300 not in page
    md = (tmp_path / "r.md").read_text()
    assert "[![captioning view](images/01_view.png)](images/01_view.png)" in md
    assert "| 6 armchair | 0.38 | 1.11 | 1.11 | chosen |" in md
    assert verdict(_items()[1]).startswith("rejected: ")
