"""``capnav map --update``: a later recording fused into a map from its observations only."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError, MapFileError
from capnav.core.frame import Frame
from capnav.io.dataset import DatasetReader
from capnav.io.mapfile import load_map, lock_map, save_map
from capnav.mapping import map_dataset
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.register import RegistrationError
from capnav.mapping.update import check_same_home, register_recording, update_map
from capnav.perception import create_detector, create_encoder
from capnav.perception.base import Detection, Detector
from capnav.sim import SceneManifest
from capnav.sim.changes import ChangeSpec
from capnav.sim.record import record_dataset

SEED = 1
SMALL = dict(rooms=3, width=160, height=120, stride=2, progress=False)


@pytest.fixture(scope="module")
def visits(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Path]]:
    d = tmp_path_factory.mktemp("visits")
    record_dataset(SEED, d / "v1", **SMALL)  # type: ignore[arg-type]
    record_dataset(SEED, d / "v2", visit=2, changes=ChangeSpec(moved=3, removed=2, added=2),
                   **SMALL)  # type: ignore[arg-type]
    record_dataset(SEED, d / "v2off", visit=2, changes=ChangeSpec(moved=3, removed=2, added=2),
                   frame_offset=(0.4, -0.3, 8.0), **SMALL)  # type: ignore[arg-type]
    record_dataset(SEED, d / "same", visit=2, changes=ChangeSpec(), **SMALL)  # type: ignore[arg-type]
    record_dataset(SEED + 1, d / "other", **SMALL)  # type: ignore[arg-type]
    m1 = map_dataset(DatasetReader(d / "v1"), _det(), _enc(), progress=False)
    save_map(m1, d / "m1.capnav")
    yield {k: d / k for k in ("v1", "v2", "v2off", "same", "other", "m1.capnav")}


def _det() -> Detector:
    return create_detector("sim", noise="oracle")  # misses are the benchmark's business (docs/change.md)


def _enc():  # type: ignore[no-untyped-def]
    from capnav.language import create_embedder

    return create_encoder("label-embedding", embedder=create_embedder("minilm"))


def _near(p: np.ndarray, q: tuple[float, ...] | None, r: float = 0.6) -> bool:
    return q is not None and float(np.hypot(p[0] - q[0], p[1] - q[1])) < r


def test_update_keeps_ids_moves_retires_and_births(visits: dict[str, Path]) -> None:
    m1 = load_map(visits["m1.capnav"])
    reader = DatasetReader(visits["v2"])
    m2, rep = update_map(m1, reader, _det(), _enc(), progress=False)
    truth = SceneManifest.load(visits["v2"] / "manifest.json").changes
    by_id = {o.id: o for o in m2.objects}
    old = {o.id: o for o in m1.objects}
    for c in truth:
        if c.kind == "moved":  # the map object at the old place now stands at the new one, same id
            ids = [i for i, o in old.items() if _near(o.position, c.old_pose) and o.label == c.category]
            assert len(ids) == 1 and ids[0] in rep.moved, (c, rep.summary())
            o = by_id[ids[0]]
            assert _near(o.position, c.new_pose) and [h["event"] for h in o.history] == ["born", "moved"]
            assert o.last_seen is not None and o.last_seen["recording"] == 2 and o.views == []
        elif c.kind == "removed":
            ids = [i for i, o in old.items() if _near(o.position, c.old_pose)]
            assert ids and set(ids) & set(rep.retired), (c, rep.summary())
            assert not any(_near(o.position, c.old_pose, 0.3) for o in m2.objects if o.label == c.category)
        else:
            born = [by_id[i] for i in rep.born if _near(by_id[i].position, c.new_pose)]
            assert born and born[0].label == c.category, (c, rep.summary())
    assert len(rep.moved) == 3 and len(rep.retired) == 2 and len(rep.born) == 2, rep.summary()
    for r in m2.retired:  # kept, with when they were last seen, never among the present
        assert r.id not in by_id and r.last_seen is not None and r.history[-1]["event"] == "retired"
    assert len(m1.retired) == 0 and [o.id for o in m1.objects] == sorted(old)  # the input is untouched
    assert rep.frames_detected < rep.frames  # unchanged stretches cost a depth check, not a detection
    ids = [o.id for o in m2.objects] + [o.id for o in m2.retired]
    assert len(ids) == len(set(ids))


def test_silence_is_not_evidence_of_absence(visits: dict[str, Path]) -> None:
    """A recording of the unchanged home by a detector that finds nothing retires nothing: only depth
    that reaches past an object's place says it is gone."""

    class Blind(Detector):
        id = "blind"

        def detect(self, frame: Frame) -> list[Detection]:
            return []

    m1 = load_map(visits["m1.capnav"])
    m2, rep = update_map(m1, DatasetReader(visits["same"]), Blind(), _enc(), progress=False)
    assert rep.retired == [] and rep.moved == [] and rep.born == []
    assert len(rep.present) >= 0.8 * len(m1.objects)
    assert all(o.last_seen and o.last_seen["recording"] == 2 for o in m2.objects if o.id in rep.present)


def test_unseen_places_stay_as_they_were(visits: dict[str, Path]) -> None:
    """Objects outside every frame of the new recording are not retired (nothing was observed)."""
    m1 = load_map(visits["m1.capnav"])
    reader = DatasetReader(visits["v2"])
    few = _Prefix(reader, 6)
    m2, rep = update_map(m1, few, _det(), _enc(), progress=False)  # type: ignore[arg-type]
    assert rep.unobserved and set(rep.unobserved) <= {o.id for o in m2.objects}
    assert len(rep.retired) <= 2


class _Prefix:
    """The first ``n`` frames of a recording (a robot that stopped early)."""

    def __init__(self, reader: DatasetReader, n: int) -> None:
        self.r, self.n = reader, n
        self.path, self.meta, self.timestamps = reader.path, reader.meta, reader.timestamps

    def __len__(self) -> int:
        return self.n

    def frame(self, i: int) -> Frame:
        return self.r.frame(i)

    def fingerprint(self) -> str:
        return "prefix-" + self.r.fingerprint()


def test_map_file_keeps_history_and_retired(visits: dict[str, Path], tmp_path: Path) -> None:
    m1 = load_map(visits["m1.capnav"])
    m2, _rep = update_map(m1, DatasetReader(visits["v2"]), _det(), _enc(), progress=False)
    p = save_map(m2, tmp_path / "m2.capnav")
    back = load_map(p)
    assert [o.id for o in back.retired] == [o.id for o in m2.retired]
    assert [o.history for o in back.objects] == [o.history for o in m2.objects]
    assert back.meta["recordings"][1]["index"] == 2 and back.meta["next_object_id"] > max(o.id for o in back.objects)
    _check_old_format_loads(tmp_path, m1)


def _check_old_format_loads(tmp_path: Path, m1: CapNavMap) -> None:
    """A version-3 file (no last_seen / history / retired) still loads, with empty history."""
    import json
    import zipfile

    src = save_map(m1, tmp_path / "v4.capnav")
    dst = tmp_path / "v3.capnav"
    with zipfile.ZipFile(src) as zi, zipfile.ZipFile(dst, "w") as zo:
        header = json.loads(zi.read("header.json"))
        recs = json.loads(zi.read("objects.json"))
        for r in recs:
            r.pop("last_seen")
            r.pop("history")
        data = json.dumps(recs).encode()
        import hashlib

        header["version"] = 3
        header["entries"]["objects.json"] = {"sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}
        for name in zi.namelist():
            if name not in ("header.json", "objects.json"):
                zo.writestr(name, zi.read(name))
        zo.writestr("objects.json", data)
        zo.writestr("header.json", json.dumps(header))
    old = load_map(dst)
    assert [o.id for o in old.objects] == [o.id for o in m1.objects]
    assert all(o.history == [] and o.last_seen is None for o in old.objects) and old.retired == []


def test_registration_of_offset_frames(visits: dict[str, Path]) -> None:
    pytest.importorskip("open3d", exc_type=ImportError,
                        reason="open3d (extra register) or a system library it needs (libusb-1.0-0) is missing")
    m1 = load_map(visits["m1.capnav"])
    reg = register_recording(m1, DatasetReader(visits["v2off"]), "v2off")
    from capnav.sim.record import planar_pose

    truth = planar_pose(0.4, -0.3, np.radians(8.0))
    assert np.abs(reg.T[:3, 3] - truth[:3, 3]).max() < 0.05, reg.to_dict()
    assert np.abs(reg.T[:3, :3] - truth[:3, :3]).max() < 0.02
    _m2, rep = update_map(m1, DatasetReader(visits["v2off"]), _det(), _enc(), transform=reg.T, progress=False)
    assert len(rep.moved) == 3 and len(rep.retired) == 2 and len(rep.born) == 2, rep.summary()


def test_bad_updates_are_refused(visits: dict[str, Path], tmp_path: Path) -> None:
    m1 = load_map(visits["m1.capnav"])
    with pytest.raises(InputError, match=r"apartment seed 2 .*apartment seed 1"):
        check_same_home(m1, DatasetReader(visits["other"]), "m1.capnav")
    with pytest.raises(InputError, match="already"):
        check_same_home(m1, DatasetReader(visits["v1"]), "m1.capnav")
    shifted = np.eye(4)
    shifted[0, 3] = 2.5  # a wrong guess, not refined: the residual says so
    with pytest.raises(RegistrationError, match=r"residual|within"):
        register_recording(m1, DatasetReader(visits["v2"]), "v2 to m1", init=shifted, icp=False)
    runner = CliRunner()
    out = tmp_path / "m2.capnav"
    res = runner.invoke(app, ["map", "--update", str(visits["m1.capnav"]), str(visits["other"]), "-o", str(out),
                              "--no-progress"])
    assert isinstance(res.exception, InputError) and "other" in str(res.exception), res.output
    assert not out.exists()


def test_concurrent_and_interrupted_updates_leave_the_map_intact(visits: dict[str, Path], tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    import shutil

    mp = tmp_path / "m.capnav"
    shutil.copy(visits["m1.capnav"], mp)
    before = mp.read_bytes()
    runner = CliRunner()
    args = ["map", "--update", str(mp), str(visits["v2"]), "-o", str(mp), "--no-progress", "--no-icp",
            "--noise", "oracle"]
    with lock_map(mp):  # another update holds the map
        res = runner.invoke(app, args)
    assert isinstance(res.exception, MapFileError) and "another process" in str(res.exception)
    assert mp.read_bytes() == before

    import capnav.mapping.update as up

    def interrupted(*a: object, **k: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(up, "update_map", interrupted)
    res = runner.invoke(app, args)
    assert res.exit_code != 0 and mp.read_bytes() == before
    assert not [p for p in tmp_path.iterdir() if p.name not in ("m.capnav", "m.capnav.lock")]
    monkeypatch.undo()
    res = runner.invoke(app, args)  # the lock died with its holder: the update goes through
    assert res.exit_code == 0, res.output
    assert len(load_map(mp).retired) == 2


def test_objects_command_and_captions_of_changed_objects_only(visits: dict[str, Path], tmp_path: Path) -> None:
    import json

    from capnav.language import create_captioner, create_embedder, describe_map

    m1 = load_map(visits["m1.capnav"])
    cap, emb = create_captioner("offline"), create_embedder("minilm")
    describe_map(m1, DatasetReader(visits["v1"]), cap, emb, progress=False)
    m2, rep = update_map(m1, DatasetReader(visits["v2"]), _det(), _enc(), progress=False)
    p = save_map(m2, tmp_path / "m2.capnav")
    before = {o.id: o.caption for o in m2.objects}
    d = describe_map(m2, DatasetReader(visits["v2"]), cap, emb, progress=False)
    # Views are chosen again only for moved and new objects; the offline captioner's words also depend
    # on the room and the neighbours, so its cache decides the rest; only changed words are embedded.
    assert d.views_selected == len(rep.moved) + len(rep.born), d.to_dict()
    assert d.captions_cached >= 1
    assert d.embeddings_new == sum(o.caption != before[o.id] for o in m2.objects), d.to_dict()
    assert all(o.caption and o.embedding is not None for o in m2.objects)

    runner = CliRunner()
    res = runner.invoke(app, ["objects", str(p), "--json"])
    assert res.exit_code == 0, res.output
    listed = json.loads(res.output)
    assert [o["id"] for o in listed["objects"]] == [o.id for o in m2.objects] and "retired" not in listed
    row = listed["objects"][0]
    assert {"id", "label", "votes", "size", "position", "caption", "views", "last_seen"} <= set(row)
    res = runner.invoke(app, ["objects", str(p), "--json", "--history"])
    h = json.loads(res.output)
    kinds = {(c["event"], c["id"]) for c in h["changes"]}
    assert kinds == ({("moved", i) for i in rep.moved} | {("retired", i) for i in rep.retired}
                     | {("born", i) for i in rep.born})
    assert [r["id"] for r in h["retired"]] == rep.retired and len(h["recordings"]) == 2
    res = runner.invoke(app, ["objects", str(p), "--history"])
    assert res.exit_code == 0 and "moved from" in res.output and "gone from" in res.output


def test_questions_about_time_answer_from_the_latest_state(visits: dict[str, Path]) -> None:
    from capnav.language import create_captioner, create_embedder, describe_map
    from capnav.retrieval.retriever import Retriever

    m1 = load_map(visits["m1.capnav"])
    cap, emb = create_captioner("offline"), create_embedder("minilm")
    describe_map(m1, DatasetReader(visits["v1"]), cap, emb, progress=False)
    m2, rep = update_map(m1, DatasetReader(visits["v2"]), _det(), _enc(), progress=False)
    describe_map(m2, DatasetReader(visits["v2"]), cap, emb, progress=False)
    r = Retriever(m2, emb)
    gone = next(o for o in m2.retired)
    res = r.query(f"where did you last see the {gone.label}")
    assert not res.found and "last seen in recording 1" in res.reason and "no longer there" in res.reason, res.reason
    moved = next(o for o in m2.objects if o.id == rep.moved[0])
    res = r.query(f"the {moved.label} that was moved")
    assert res.found and res.chosen is not None and res.chosen.id in rep.moved and "last seen in visit 2" in res.reason
    res = r.query("what is new")
    assert res.found and res.chosen is not None and res.chosen.id in rep.born
    room = r._scoped["new"].scene.room_of(res.chosen)
    if room:
        res = r.query(f"what is new in the {room}")
        assert res.found and res.chosen is not None and res.chosen.id in rep.born and room in res.reason
    # without time words, the present state answers and a retired object is never returned
    for o in m2.objects:
        res = r.query(f"the {o.label}")
        assert res.chosen is None or res.chosen.id not in {g.id for g in m2.retired}
    assert not Retriever(m1, emb)._time  # a one-recording map reads requests exactly as before


def test_identity_scorer_reads_ids_from_points_not_from_the_simulator(visits: dict[str, Path]) -> None:
    """``eval.update_identity`` matches both maps to the truth by their points (a COCO model's map
    carries no instance ids): the oracle update is right in every class, and the same map with a
    moved object's id changed is scored as reborn, not kept."""
    from capnav.eval.update_identity import identity_report

    m1 = load_map(visits["m1.capnav"])
    m2, rep = update_map(m1, DatasetReader(visits["v2"]), _det(), _enc(), progress=False)
    t1, t2 = (SceneManifest.load(visits[k] / "manifest.json") for k in ("v1", "v2"))
    score = identity_report(m1, m2, t1, t2)
    for cls in ("moved", "removed", "added"):
        ok, n = score.right(cls)
        assert n > 0 and ok == n, (cls, score.counts)
    ok, n = score.right("unchanged")
    assert ok == n and n >= 5, score.counts
    renamed = next(o for o in m2.objects if o.id in rep.moved)
    renamed.id = 999
    again = identity_report(m1, m2, t1, t2)
    assert again.counts["moved"]["reborn"] == 1 and again.right("moved")[0] == score.right("moved")[0] - 1
