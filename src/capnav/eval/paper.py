"""The paper's published numbers (Tables 1 and 2), printed beside ours in every report.

They were measured in Habitat on Matterport3D with Detic, LSeg, BGE-M3 and Gemini; ours come from
CapNav's procedural apartments and simulated detector, so only the comparison between methods
within one table is meaningful, not the absolute values across tables.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PaperRow:
    label: str
    in_a_row: tuple[float, float, float, float]  # percent
    independent: float  # percent


#: Table 1 of the paper (label-only protocol), keyed by our method name.
TABLE1: dict[str, PaperRow] = {
    "lmnav": PaperRow("LM-Nav", (25, 6, 0, 0), 8.5),
    "zson": PaperRow("ZSON", (11, 2, 0, 0), 9.34),
    "cow": PaperRow("CLIP on Wheels (CoW)", (22, 7, 1, 0), 19.8),
    "vlmaps": PaperRow("VLMaps", (46, 27, 16, 5), 48.1),
    "capnav": PaperRow("CapNav", (62, 40, 22, 14), 56.6),
}

#: Table 2 of the paper: (full-chain success rate %, subgoal success rate %).
TABLE2: dict[str, tuple[str, float, float]] = {
    "capnav": ("CapNav (full)", 15.4, 56.6),
    "capnav-no-verify": ("w/o AGENT reranking", 7.7, 51.9),
    "capnav-no-heuristic": ("w/o attribute heuristic", 15.1, 56.0),
}

#: The paper's benchmark size, for the report header.
PAPER_SETUP = {"scenes": 10, "episodes": 91, "subgoals": 364, "categories": 31, "frames": 11206}
