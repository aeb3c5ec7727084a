"""Robots' maps as the page fetches them (cyborg.monitor.map_store, map_route): the blob's layout
read back as the page reads it, maps the monitor will not draw refused whole with a warning,
keys computed by the monitor (a forged hash changes nothing), a bounded store that keeps the
maps robots use, and GET /api/map/{key} with immutable caching, ETag and 304, gzip and 404."""

from __future__ import annotations

import gzip
import json
import math
import struct
from typing import Any

import numpy as np
import pytest

from cyborg.bus.msgs.cyborg_msgs.msg import MapObject
from cyborg.monitor.map_route import CACHE_CONTROL, accepts_gzip, matches_etag
from cyborg.monitor.map_store import (
    FORMAT,
    MAGIC,
    POINT_LIMIT,
    MapRefusedError,
    MapStore,
    map_blob,
    map_key,
)
from cyborg.monitor.server import create_app
from tests.monitor.monitor_protocol import bare_hub, local_client
from tests.monitor.robot_messages import map_geometry, map_object


def parse_blob(blob: bytes) -> tuple[dict[str, Any], np.ndarray, np.ndarray]:
    """The blob as the page reads it: header, lines (n x 4) and points (n x 2)."""
    assert blob[:8] == MAGIC
    (length,) = struct.unpack_from("<I", blob, 8)
    assert length % 4 == 0
    header = json.loads(blob[12:12 + length].decode())
    start = 12 + length
    counts = header["counts"]
    lines = np.frombuffer(blob, "<f4", counts["lines"] * 4, start).reshape(-1, 4)
    points = np.frombuffer(blob, "<f4", counts["points"] * 2,
                           start + counts["lines"] * 16).reshape(-1, 2)
    assert len(blob) == start + counts["lines"] * 16 + counts["points"] * 8
    return header, lines, points


# ---------------------------------------------------------------------------------- the blob
def test_a_map_round_trips_through_its_blob() -> None:
    message = map_geometry(source="/home/robot/maps/small.map")
    blob, header, warnings = map_blob(message)
    assert warnings == []
    parsed, lines, points = parse_blob(blob)
    assert parsed == header
    assert parsed["format"] == FORMAT and parsed["source"] == "small.map"
    assert parsed["frame"] == "map" and parsed["resolution"] == pytest.approx(0.05)
    assert parsed["counts"] == {"lines": 2, "points": 3, "objects": 2}
    assert lines.tolist() == [[0, 0, 10, 0], [10, 0, 10, 5]]
    assert points.tolist() == [[1, 1], [2.5, 3], [-1, 4]]
    assert parsed["bounds"] == [-1.0, 0.0, 10.0, 5.0]
    goal, area = parsed["objects"]
    assert goal == {"kind": "Goal", "category": MapObject.GOAL, "name": "Office",
                    "description": "", "pose": [1.0, 2.0, 0.0], "outline": []}
    assert area["category"] == MapObject.FORBIDDEN_AREA
    assert area["outline"] == [4.0, 0.0, 6.0, 0.0, 6.0, 2.0, 4.0, 2.0]


def test_an_empty_map_has_zero_bounds() -> None:
    blob, header, _ = map_blob(map_geometry(lines=(), points=(), objects=[]))
    assert header["bounds"] == [0.0, 0.0, 0.0, 0.0] and parse_blob(blob)[0] == header


def test_a_forged_hash_does_not_change_the_key_and_the_same_map_shares_one() -> None:
    store = MapStore()
    first, _ = store.put(map_geometry(hash_="sha256:" + "0" * 64))
    second, _ = store.put(map_geometry(hash_="sha256:forged"))
    other, _ = store.put(map_geometry(points=(1.0, 1.0, 2.5, 3.0, -1.0, 4.001)))
    assert first is not None and second is not None and other is not None
    assert first.key == second.key == map_key(map_blob(map_geometry())[0])
    assert other.key != first.key and len(store) == 2
    assert first.url == f"/api/map/{first.key}" and len(first.key) == 32


@pytest.mark.parametrize(("message", "said"), [
    (lambda: map_geometry(points=np.zeros(POINT_LIMIT * 5 * 2, np.float32)),
     "map: 10,000,000 points, more than the 2,000,000 the monitor draws; map not shown"),
    (lambda: map_geometry(points=(1.0, math.nan)), "not finite (nan)"),
    (lambda: map_geometry(lines=(0.0, 0.0, 1e12, 0.0)),
     "reach 1e+12 m from the origin, more than the 10 km"),
    (lambda: map_geometry(points=(1.0, 2.0, 3.0)), "points has 3 numbers, not a multiple of 2"),
    (lambda: map_geometry(lines=(1.0, 2.0)), "lines has 2 numbers, not a multiple of 4"),
    (lambda: map_geometry(objects=[map_object(outline=(1.0, 2.0, 3.0, 4.0, 5.0))]),
     "object 0 ('Office') has an outline of 5 numbers; expected 0, 4 or 8"),
    (lambda: map_geometry(objects=[map_object(at=(math.inf, 0.0, 0.0))]),
     "has a pose that is not finite"),
    (lambda: map_geometry(objects=[map_object(at=(0.0, 0.0, math.nan))]),
     "has a pose that is not finite"),
    (lambda: map_geometry(objects=[map_object(outline=(0.0, 0.0, 0.0, 1e9))]),
     "outline reach 1e+09 m"),
    (lambda: map_geometry(objects=[map_object()] * 10_001),
     "10,001 objects, more than the 10,000"),
])
def test_an_absurd_map_is_refused_whole_with_a_warning(message: Any, said: str) -> None:
    with pytest.raises(MapRefusedError):
        map_blob(message())
    store = MapStore()
    stored, warnings = store.put(message())
    assert stored is None and len(store) == 0
    assert len(warnings) == 1 and said in warnings[0], warnings


def test_odd_objects_are_drawn_with_a_warning() -> None:
    message = map_geometry(objects=[map_object("n" * 500, category=42, kind="Weird")])
    message.resolution = math.nan
    _blob, header, warnings = map_blob(message)
    assert header["objects"][0]["category"] == MapObject.OTHER
    assert len(header["objects"][0]["name"]) == 200 and header["resolution"] == 0.0
    assert len(warnings) == 3, warnings


def test_the_store_keeps_few_maps_but_never_one_in_use() -> None:
    store = MapStore(maps=2)
    keys: list[str] = []
    for index in range(4):
        stored, _ = store.put(map_geometry(points=(float(index), 0.0)), in_use=keys[:1])
        assert stored is not None
        keys.append(stored.key)
    assert keys[0] in store, "in use: kept"
    assert keys[1] not in store and keys[2] not in store and keys[3] in store
    assert store.get(keys[3]) is not None and store.get("f" * 32) is None


def test_the_store_keeps_a_bounded_number_of_bytes() -> None:
    store = MapStore(size=1)
    first, _ = store.put(map_geometry(points=(1.0, 0.0)))
    second, _ = store.put(map_geometry(points=(2.0, 0.0)))
    assert first is not None and second is not None
    assert first.key not in store and second.key in store, "the newest stays, even over"


# ---------------------------------------------------------------------------------- the route
def test_the_map_route_caches_for_good_answers_304_and_gzips() -> None:
    hub = bare_hub()
    stored, _ = hub.robot_hub.store.put(map_geometry())
    assert stored is not None
    with local_client(create_app(hub)) as client:
        plain = client.get(stored.url, headers={"accept-encoding": "identity"})
        assert plain.status_code == 200
        assert plain.headers["cache-control"] == CACHE_CONTROL
        assert plain.headers["etag"] == f'"{stored.key}"'
        assert plain.headers["content-type"] == "application/octet-stream"
        assert "content-encoding" not in plain.headers
        assert map_key(plain.content) == stored.key
        zipped = client.get(stored.url, headers={"accept-encoding": "gzip, deflate"})
        assert zipped.headers["content-encoding"] == "gzip"
        assert zipped.content == plain.content, "the client unzips what it accepted"
        assert int(zipped.headers["content-length"]) == len(stored.gzipped)
        again = client.get(stored.url, headers={"if-none-match": f'"{stored.key}"'})
        assert again.status_code == 304 and again.content == b""
        assert again.headers["etag"] == f'"{stored.key}"'
        assert client.get("/stats").json()["map_fetches"] == 2, "a 304 fetches nothing"
        for missing in ("0" * 32, "nothex", "0" * 31 + "g", stored.key.upper()):
            answer = client.get(f"/api/map/{missing}")
            assert answer.status_code == 404 and "no such map" in answer.json()["error"]
        assert client.get("/api/map/../../etc/passwd").status_code == 404


def test_the_map_route_is_behind_the_host_guard() -> None:
    hub = bare_hub()
    stored, _ = hub.robot_hub.store.put(map_geometry())
    assert stored is not None
    with local_client(create_app(hub), base_url="http://rebind.attacker.example:8080") as client:
        assert client.get(stored.url).status_code == 403


def test_accept_encoding_and_if_none_match_are_read_as_http_says() -> None:
    assert accepts_gzip("gzip") and accepts_gzip("deflate, gzip;q=0.5") and accepts_gzip("*")
    assert not accepts_gzip(None) and not accepts_gzip("gzip;q=0") and not accepts_gzip("br")
    assert not accepts_gzip("gzip;q=zero")
    assert matches_etag('"a", W/"b"', '"b"') and matches_etag("*", '"x"')
    assert not matches_etag('"a"', '"b"') and not matches_etag(None, '"b"')


def test_a_stored_blob_is_the_gzip_of_what_is_served() -> None:
    store = MapStore()
    stored, _ = store.put(map_geometry())
    assert stored is not None
    blob = gzip.decompress(stored.gzipped)
    assert len(blob) == stored.size and map_key(blob) == stored.key
