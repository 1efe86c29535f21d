"""A map made by a closed-vocabulary detector records the labels it could output; the simulator
detector (any category) records none, so its maps stay as they were."""

from __future__ import annotations

from _synth_scene import orbit

from capnav.mapping import Mapper, MapperConfig
from capnav.perception import Detector, create_detector, create_encoder


class _Closed(Detector):
    """The simulator's detections, from a detector that says it knows only three labels."""

    id = "closed-test"
    labels = frozenset({"chair", "sofa", "vase"})

    def __init__(self) -> None:
        self.inner = create_detector("sim", noise="oracle")

    def detect(self, frame):  # type: ignore[no-untyped-def]
        return self.inner.detect(frame)


def _map(embedder, detector: Detector):  # type: ignore[no-untyped-def]
    m = Mapper(MapperConfig(), detector, create_encoder("label-embedding", embedder=embedder))
    for f in orbit(4):
        m.integrate(f)
    return m.finish()


def test_a_closed_vocabulary_is_recorded_in_the_map(embedder) -> None:  # type: ignore[no-untyped-def]
    assert _map(embedder, _Closed()).meta["detector_labels"] == ["chair", "sofa", "vase"]


def test_the_simulator_detector_records_no_vocabulary(embedder) -> None:  # type: ignore[no-untyped-def]
    assert "detector_labels" not in _map(embedder, create_detector("sim", noise="oracle")).meta
