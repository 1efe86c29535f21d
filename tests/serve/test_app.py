"""The server's endpoints through Starlette's test client (the app as uvicorn runs it, no socket)."""

from __future__ import annotations

from pathlib import Path

import pytest
from starlette.testclient import TestClient

from capnav.serve import ServeConfig, create_app
from capnav.serve.limits import RateLimit


@pytest.fixture(scope="module")
def client(served_map: Path):
    with TestClient(create_app(served_map)) as c:  # the context runs the start-up warm-up
        yield c


def test_page_and_static_files(client: TestClient) -> None:
    r = client.get("/")
    assert r.status_code == 200 and 'id="q"' in r.text and "/static/app.js" in r.text
    assert "http" not in r.text.replace("http://www.w3.org", "")  # no CDN: everything from this server
    assert "default-src 'self'" in r.headers["content-security-policy"]
    assert "access-control-allow-origin" not in r.headers
    assert client.get("/static/app.js").headers["content-type"].startswith("text/javascript")
    assert client.get("/static/../api.py").status_code == 404
    assert client.get("/static/nope.js").json()["error"].startswith("no page file")


def test_map_objects_and_health(client: TestClient) -> None:
    assert client.get("/healthz").json() == {"ok": True, "objects": 7}
    ready = client.get("/readyz")
    assert ready.status_code == 200 and ready.json()["ready"] and ready.json()["maps"][0]["name"] == "living"
    assert client.get("/api/maps").json()["default"] == "living"
    m = client.get("/api/map").json()
    assert m["grid"]["resolution"] == 0.05 and m["objects"] == 7 and m["captioned"]
    pic = m["picture"]
    png = client.get("/api/map.png")
    assert png.headers["content-type"] == "image/png" and png.content[:8] == b"\x89PNG\r\n\x1a\n"
    import io

    from PIL import Image

    assert Image.open(io.BytesIO(png.content)).size == (pic["width"], pic["height"])
    x, y = m["default_robot"]
    assert -1 < x < 9 and -1 < y < 7
    objs = client.get("/api/objects").json()["objects"]
    assert [o["id"] for o in objs] == [1, 2, 3, 4, 5, 6, 7] and objs[0]["caption"].startswith("SOFA")
    assert client.get("/api/objects/1/view.png").status_code == 404  # synthetic objects have no views
    assert client.get("/api/objects/99/view.png").status_code == 404


def test_query_answers_with_plan(client: TestClient) -> None:
    r = client.post("/api/query", json={"text": "the red sofa", "k": 2, "robot": [6.0, 3.0]})
    assert r.status_code == 200, r.text
    d = r.json()
    assert d["found"] and d["chosen"]["id"] == 1 and "Chose object 1" in d["reason"]
    assert d["object"] == d["chosen"] and d["robot_note"] == ""  # "object": the old name, kept one release
    assert all(r["why"] and "similarity" in r["terms"] for r in d["runners_up"])  # why each one lost
    assert len(d["runners_up"]) <= 2 and all(o["id"] != 1 for o in d["runners_up"])
    assert d["goal"]["reached_within_reach"] and d["plan"]["success"] and d["plan"]["target"] == 1
    assert d["plan"]["poses"][0][:2] == [6.0, 3.0] and d["plan"]["length_m"] > 2.0
    d = client.post("/api/query", json={"text": "the red sofa"}).json()
    assert d["found"] and d["plan"] is None and "no robot position" in d["goal_note"]
    d = client.post("/api/query", json={"text": "the red sofa", "robot": [3.8, 6.0]}).json()
    assert d["found"] and "inside an obstacle; moved" in d["robot_note"]  # in the wall: the nearest free cell
    assert d["plan"]["success"] and d["plan"]["poses"][0][:2] != [3.8, 6.0]
    d = client.post("/api/query", json={"text": "the piano", "robot": [6.0, 3.0]}).json()
    assert not d["found"] and d["plan"] is None and d["reason"].startswith("Not found")
    p = client.post("/api/plan", json={"start": [6.0, 3.0, 0.0], "object": 7}).json()
    assert p["success"] and p["target"] == 7


@pytest.mark.parametrize(("body", "status", "why"), [
    ({"k": 3}, 422, "'text'"),
    ({"text": 5}, 422, "'text'"),
    ({"text": "   "}, 422, "empty instruction"),
    ({"text": "sofa " * 200}, 422, "too long"),
    ({"text": "the sofa", "k": 99}, 422, "'k'"),
    ({"text": "the sofa", "k": True}, 422, "'k'"),
    ({"text": "the sofa", "robot": [1, "a"]}, 422, "robot must be"),
    ({"text": "the sofa", "robot": [100.0, 100.0]}, 422, "is off the map"),  # as a start off the map for /api/plan
    ({"text": "the sofa", "robot": [1.0, 2.0, 3.0, 4.0]}, 422, "robot must be"),
])
def test_bad_query_input_is_a_4xx_with_the_reason(client: TestClient, body: dict, status: int, why: str) -> None:
    r = client.post("/api/query", json=body)
    assert r.status_code == status, r.text
    assert why in r.json()["error"]


def test_bad_bodies(client: TestClient) -> None:
    r = client.post("/api/query", content=b"{not json", headers={"content-type": "application/json"})
    assert r.status_code == 400 and "not valid JSON" in r.json()["error"]
    r = client.post("/api/query", content=b"text=sofa", headers={"content-type": "application/x-www-form-urlencoded"})
    assert r.status_code == 415
    r = client.post("/api/query", content=b'{"text": "the sofa", "robot": [1e400, 0]}',
                    headers={"content-type": "application/json"})
    assert r.status_code == 422 and "finite" in r.json()["error"]
    r = client.post("/api/query", json=["the sofa"])
    assert r.status_code == 422 and "JSON object" in r.json()["error"]
    r = client.post("/api/query", json={"text": "x" * 20_000})
    assert r.status_code == 413 and "over 16384 bytes" in r.json()["error"]
    assert client.post("/api/plan", json={"start": [6, 3], "object": 99}).status_code == 404
    assert client.get("/api/query").status_code == 405


def test_streamed_body_over_the_limit(served_map: Path) -> None:
    def chunks():
        for _ in range(40):
            yield b"x" * 1000

    with TestClient(create_app(served_map, ServeConfig(max_body=4096, warm_up=False))) as c:
        r = c.post("/api/query", content=chunks(), headers={"content-type": "application/json"})
        assert r.status_code == 413


def test_rate_limit(served_map: Path) -> None:
    with TestClient(create_app(served_map, ServeConfig(rate=1.0, burst=3, warm_up=False))) as c:
        codes = [c.get("/healthz").status_code for _ in range(5)]
        assert codes[:3] == [200, 200, 200] and codes[3:] == [429, 429]
        r = c.get("/healthz")
        assert r.status_code == 429 and int(r.headers["retry-after"]) >= 1 and "too many requests" in r.json()["error"]


def test_token_bucket_refills() -> None:
    t = [0.0]
    rl = RateLimit(None, rate=2.0, burst=2, clock=lambda: t[0])  # type: ignore[arg-type]
    assert rl.take("a") == 0 and rl.take("a") == 0 and rl.take("a") == pytest.approx(0.5)
    assert rl.take("b") == 0  # per client
    t[0] = 0.5
    assert rl.take("a") == 0 and rl.take("a") > 0


def test_starts_like_navigate_on_a_map_with_a_camera_path(served_map: Path) -> None:
    """The page's default robot and a plan without a start are the map's last camera pose, and
    plans go through unknown floor the camera walked (the same grid as ``capnav navigate``)."""
    from capnav.api import CapNav
    from capnav.planning.config import PlannerConfig
    from language.synth import walked_through_the_door

    nav = CapNav(walked_through_the_door(served_map), planner=PlannerConfig(unknown_cost=None))
    with TestClient(create_app(nav, ServeConfig(warm_up=False))) as c:
        assert c.get("/api/map").json()["default_robot"] == [6.0, 3.0]
        p = c.post("/api/plan", json={"object": 1}).json()
        assert p["success"] and p["poses"][0][:2] == [6.0, 3.0] and p["target"] == 1
        d = c.post("/api/query", json={"text": "the red sofa", "robot": [6.0, 3.0]}).json()
        assert d["chosen"]["id"] == 1 and d["plan"]["success"] and d["plan"]["poses"][-1] == p["poses"][-1]
    with TestClient(create_app(served_map, ServeConfig(warm_up=False))) as c:  # no camera path: a start is needed
        r = c.post("/api/plan", json={"object": 1})
        assert r.status_code == 422 and "records no camera path" in r.json()["error"]
