"""Live maps through a real uvicorn: a replaced map file is reloaded without dropping asks, a bad
replacement keeps the served map, maps with unusable embeddings are refused, several maps are
served by name."""

from __future__ import annotations

import shutil
import threading
from pathlib import Path

import httpx
import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.io.mapfile import load_map, save_map
from capnav.serve import ServeConfig, create_app
from serve.live import live

CFG = ServeConfig(workers=2, rate=0)


def _without_last_object(src: Path, dest: Path) -> None:
    cmap = load_map(src)
    cmap.objects = cmap.objects[:-1]
    save_map(cmap, dest)


@pytest.mark.parametrize("pool", ["threads", "processes"])
def test_reload_swaps_a_replaced_file_without_dropping_asks(served_map: Path, tmp_path: Path, pool: str) -> None:
    path = tmp_path / "home.capnav"
    shutil.copy(served_map, path)
    with live(create_app(path, ServeConfig(workers=2, rate=0, pool=pool))) as (url, _):
        assert httpx.get(url + "/api/map").json()["version"] == 1
        codes: list[int] = []
        stop = threading.Event()

        def asking() -> None:
            with httpx.Client(base_url=url, timeout=30) as c:
                while not stop.is_set() and len(codes) < 200:
                    codes.append(c.post("/api/query", json={"text": "the red sofa", "robot": [6.0, 3.0]}).status_code)

        t = threading.Thread(target=asking)
        t.start()
        try:
            _without_last_object(served_map, path)
            r = httpx.post(url + "/api/reload", timeout=60)
            assert r.status_code == 200 and r.json()["maps"]["home"].startswith("reloaded (version 2, 6 objects)")
            after = httpx.post(url + "/api/query", json={"text": "the red sofa"}, timeout=30).json()
            assert after["map_version"] == 2 and after["found"]
        finally:
            stop.set()
            t.join(60)
        assert codes and set(codes) == {200}  # every ask before, during and after the swap answered
        assert httpx.get(url + "/api/map").json()["objects"] == 6
        assert httpx.post(url + "/api/reload").json()["maps"]["home"] == "unchanged (version 2)"

        path.write_bytes(b"not a map")  # a broken replacement: refused, version 2 still served
        r = httpx.post(url + "/api/reload", timeout=60)
        assert r.status_code == 422 and "still serving version 2" in r.json()["maps"]["home"]
        assert httpx.post(url + "/api/query", json={"text": "the red sofa"}, timeout=30).json()["map_version"] == 2


@pytest.mark.parametrize(("scale", "why"), [(0.0, "all-zero caption embeddings"), (3.0, "not unit vectors")])
def test_unusable_embeddings_are_refused_at_load(served_map: Path, tmp_path: Path, scale: float, why: str) -> None:
    cmap = load_map(served_map)
    for o in cmap.objects:
        o.embedding = (np.asarray(o.embedding) * scale).astype(np.float32)
    bad = save_map(cmap, tmp_path / "bad.capnav")  # checksums are valid: the file is intact
    with pytest.raises(InputError, match=why):
        create_app(bad, CFG)


def test_several_maps_by_name(served_map: Path, tmp_path: Path) -> None:
    other = tmp_path / "floor2.capnav"
    _without_last_object(served_map, other)
    with pytest.raises(InputError, match="would both be served as"):
        create_app([served_map, served_map], CFG)
    with live(create_app([served_map, other], CFG)) as (url, _):
        maps = httpx.get(url + "/api/maps").json()
        assert maps["default"] == "living" and [m["name"] for m in maps["maps"]] == ["living", "floor2"]
        assert httpx.get(url + "/api/maps/floor2/map").json()["objects"] == 6
        assert httpx.get(url + "/api/map").json()["objects"] == 7  # the unnamed routes: the first map
        assert len(httpx.get(url + "/api/maps/floor2/objects").json()["objects"]) == 6
        d = httpx.post(url + "/api/maps/floor2/query", json={"text": "the red sofa", "robot": [6.0, 3.0]},
                       timeout=30).json()
        assert d["map"] == "floor2" and d["chosen"]["id"] == 1 and d["plan"]["success"]
        p = httpx.post(url + "/api/maps/floor2/plan", json={"start": [6.0, 3.0], "object": 1}, timeout=30).json()
        assert p["success"] and p["target"] == 1
        r = httpx.post(url + "/api/maps/nope/query", json={"text": "the red sofa"})
        assert r.status_code == 404 and "living, floor2" in r.json()["error"]
        assert httpx.get(url + "/api/maps/floor2/map.png").content[:4] == b"\x89PNG"
