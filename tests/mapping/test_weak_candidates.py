"""Low-score candidates confirmed by several frames (failure class from real recordings, issue 21:
a COCO detector scores real tables at 0.17-0.20 and ICL-NUIM's vase at 0.15-0.23 in all but one
frame, below the 0.3 threshold, so the thing is never an object however often it is seen).

A detector's boxes between its candidate floor and its threshold come as ``Detection.weak``; the
mapper confirms a place from them only by ``weak_h_min`` sightings agreeing in 3D, one of them
confident, whose leading label sums ``weak_score`` and holds ``weak_agreement`` of the label
scores read on those boxes; a weak vote never outvotes a confident one, and a one-frame map keeps
no weak candidate. The scripted detector below wraps the simulator's oracle detector and sets the
scores; the scene and the numbers are ours."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from _synth_scene import Box, render

from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.io.dataset import DatasetWriter
from capnav.mapping import Mapper, MapperConfig, map_dataset
from capnav.mapping.tracker import TrackerConfig
from capnav.perception import create_detector, create_encoder
from capnav.perception.base import Detection, Detector
from capnav.perception.coco_detector import rival_readings

# A dining table (category 5) 2 m ahead of the cameras and a chair (category 3) beside it.
TABLE = Box((1.6, -0.5, 0.0), (2.6, 0.3, 0.74), 1, 5, (150, 100, 60))
CHAIR = Box((1.7, 0.6, 0.0), (2.15, 1.05, 0.9), 2, 3, (40, 40, 160))
K = Intrinsics.from_fov(160, 120, 60.0)
N = 12


def _frames(n: int = N) -> list[Frame]:
    """Cameras stepping sideways at 1.2 m, all looking at the table."""
    return [render([TABLE, CHAIR], look_at_pose(np.array([0.0, -0.6 + 0.08 * i, 1.2]), yaw=0.05 * (i % 3),
                                                 pitch=np.deg2rad(25)), K, index=i) for i in range(n)]


class Scripted(Detector):
    """The oracle detector with the table's score set per frame (``table``: frame -> score, or
    frame -> label votes), the chair at 0.6, and a clutter false positive ("refrigerator" on a
    patch of the wall) at ``clutter`` score in the frames ``clutter_frames``."""

    id = "scripted"
    needs_truth = True

    def __init__(self, table: dict[int, float | dict[str, float]], clutter_frames: tuple[int, ...] = (),
                 clutter: float = 0.2, table_label: str = "table") -> None:
        self.inner = create_detector("sim", noise="oracle", seed=0)
        self.table, self.clutter_frames, self.clutter, self.table_label = table, clutter_frames, clutter, table_label

    def detect(self, frame: Frame) -> list[Detection]:
        return [d for d in self.detect_candidates(frame) if not d.weak]

    def detect_candidates(self, frame: Frame) -> list[Detection]:
        out: list[Detection] = []
        for d in self.inner.detect(frame):
            if d.label == "chair":
                out.append(replace(d, score=0.6))
            elif d.label == "table" and frame.index in self.table:
                s = self.table[frame.index]
                votes = s if isinstance(s, dict) else {self.table_label: float(s)}
                lead = max(votes, key=lambda k: votes[k])
                out.append(replace(d, label=lead, score=votes[lead], votes=votes if len(votes) > 1 else {},
                                   weak=votes[lead] < 0.3))
        if frame.index in self.clutter_frames:
            mask = np.zeros(frame.shape, dtype=bool)
            mask[2:22, 10:40] = True  # wall above the table, nothing there
            out.append(Detection((10.0, 2.0, 40.0, 22.0), 0, "refrigerator", self.clutter, mask, weak=True))
        return out


def _map(det: Detector, embedder, tracker: TrackerConfig | None = None, n: int = N):  # type: ignore[no-untyped-def]
    m = Mapper(MapperConfig(tracker=tracker or TrackerConfig()), det, create_encoder("label-embedding",
                                                                                    embedder=embedder))
    for f in _frames(n):
        m.integrate(f)
    return m.finish()


def _labels(cmap) -> list[str]:  # type: ignore[no-untyped-def]
    return sorted(o.label for o in cmap.objects)


def test_a_table_scored_low_in_many_frames_is_an_object_and_a_one_off_is_not(embedder) -> None:  # type: ignore[no-untyped-def]
    table: dict[int, float | dict[str, float]] = {i: 0.2 for i in range(N)}
    table[4] = 0.32  # confident once, like the ICL vase: one sighting, not h_min of them
    cmap = _map(Scripted(table, clutter_frames=(5,)), embedder)
    assert _labels(cmap) == ["chair", "table"]
    (t,) = cmap.by_label("table")
    np.testing.assert_allclose(t.position[:2], [2.1, -0.1], atol=0.3)
    assert t.hits >= 5 and cmap.meta["weak_confirmed_tracks"] >= 1


def test_clutter_seen_as_often_as_it_is_weak_stays_out(embedder) -> None:  # type: ignore[no-untyped-def]
    """A false positive repeated at 0.2 in every frame never has a confident sighting: not an object."""
    cmap = _map(Scripted({4: 0.32}, clutter_frames=tuple(range(N))), embedder)
    assert _labels(cmap) == ["chair"]  # and the table, confident once, stays below h_min too
    assert cmap.meta["weak_confirmed_tracks"] == 0


def test_weak_sightings_alone_need_weak_confident_zero(embedder) -> None:  # type: ignore[no-untyped-def]
    """This scene's table is a solid block (closed below, a cabinet's shape), so its shape does not
    confirm it either (``TrackerConfig.weak_shape``; tables on legs: test_weak_shape.py)."""
    table: dict[int, float | dict[str, float]] = {i: 0.2 for i in range(N)}
    assert _labels(_map(Scripted(table), embedder)) == ["chair"]
    assert _labels(_map(Scripted(table), embedder, TrackerConfig(weak_confident=0))) == ["chair", "table"]
    assert _labels(_map(Scripted(table), embedder, TrackerConfig(weak_h_min=0))) == ["chair"]


def test_a_place_read_as_several_classes_is_not_confirmed(embedder) -> None:  # type: ignore[no-untyped-def]
    """The model reads the same box as table, chair and sofa in turn: the table's share of those
    readings (0.2 of 0.53) is no agreement."""
    table: dict[int, float | dict[str, float]] = {i: {"table": 0.2, "chair": 0.18, "sofa": 0.15} for i in range(N)}
    table[4] = 0.32
    assert _labels(_map(Scripted(table), embedder)) == ["chair"]


def test_weak_votes_never_outvote_a_confident_label(embedder) -> None:  # type: ignore[no-untyped-def]
    """Three confident "table" sightings and nine weak "desk" ones (a lookalike, so one track):
    the desk's votes sum higher, the object is still the table."""
    table: dict[int, float | dict[str, float]] = {i: {"desk": 0.29} for i in range(N)}
    for i in (2, 6, 10):
        table[i] = 0.4
    cmap = _map(Scripted(table), embedder)
    assert _labels(cmap) == ["chair", "table"]
    (t,) = cmap.by_label("table")
    assert set(t.label_votes) == {"table"}


def test_a_one_frame_recording_keeps_no_weak_candidate(tmp_path: Path, embedder) -> None:  # type: ignore[no-untyped-def]
    frame = _frames(1)[0]
    with DatasetWriter(tmp_path / "one", frame.K) as w:
        w.write(frame)
    det = Scripted({0: 0.29}, clutter_frames=(0,), clutter=0.29)
    cmap = map_dataset(tmp_path / "one", det, create_encoder("label-embedding", embedder=embedder), progress=False)
    assert cmap.meta["h_min_used"] == 1
    assert _labels(cmap) == ["chair"]


def test_rival_readings_of_one_box_become_the_candidates_votes() -> None:
    boxes = np.array([[0, 0, 100, 100], [1, 0, 100, 100], [0, 1, 100, 99], [200, 0, 300, 80], [0, 0, 99, 100],
                      [400, 0, 450, 50]], dtype=np.float64)
    scores = np.array([0.17, 0.16, 0.12, 0.5, 0.6, 0.12])
    labels = ["table", "chair", "bed", "tv", "sofa", "cup"]
    keep, votes = rival_readings(boxes, scores, labels, threshold=0.3, floor=0.15)
    # Confident boxes as they are; the table takes the chair and bed read on its box; the lone cup
    # at 0.12 is below the floor and taken by no candidate.
    assert [labels[k] for k in keep] == ["sofa", "tv", "table"]
    assert votes[2] == {"table": 0.17, "chair": 0.16, "bed": 0.12} and votes[0] == {} and votes[1] == {}


def test_the_cli_takes_tracker_options(tmp_path: Path) -> None:
    """``capnav map --tracker-option`` sets the confirmation (e.g. ``weak_confident=0`` for a
    recording whose tables are never scored at the threshold); unknown keys are refused by name."""
    from typer.testing import CliRunner

    from capnav.cli import app
    from capnav.io.mapfile import load_map

    frames = _frames(4)
    with DatasetWriter(tmp_path / "rec", frames[0].K) as w:
        for f in frames:
            w.write(f)
    out = tmp_path / "m.capnav"
    base = ["map", str(tmp_path / "rec"), "-o", str(out), "--noise", "oracle", "--no-progress"]
    r = CliRunner().invoke(app, [*base, "--tracker-option", "weak_confident=0", "--tracker-option", "weak_h_min=6"])
    assert r.exit_code == 0, r.output
    tracker = load_map(out, voxels=False).meta["config"]["tracker"]
    assert tracker["weak_confident"] == 0 and tracker["weak_h_min"] == 6
    r = CliRunner().invoke(app, [*base, "--tracker-option", "weak_min=3"])
    assert r.exit_code != 0 and "weak_min" in r.output + str(r.exception)
    r = CliRunner().invoke(app, [*base, "--tracker-option", "weak_h_min=2"])  # below h_min
    assert r.exit_code != 0 and "weak_h_min" in r.output + str(r.exception)
