"""The page's files (:mod:`cyborg.monitor.page_files`): served from memory by default, with
Starlette's StaticFiles as the fallback, and both alike: every file of the folder with its own
bytes and media type, revalidated with an ETag (a reload costs a 304), nothing outside the
folder, and the Host check in front of it all."""

from __future__ import annotations

import posixpath
import re

import pytest
from starlette.types import ASGIApp

from cyborg.monitor.access import HostPolicy
from cyborg.monitor.page_files import (
    MEDIA_TYPES,
    STATIC,
    PageCache,
    PageFiles,
    page_files,
)
from cyborg.monitor.server import create_app
from tests.monitor.monitor_protocol import bare_hub, local_client

PAGE_FILES = sorted(path.relative_to(STATIC).as_posix()
                    for path in STATIC.rglob("*") if path.is_file())
WAYS = ["memory", "StaticFiles"]


def _app(way: str, hosts: HostPolicy | None = None) -> ASGIApp:
    return create_app(bare_hub(), hosts=hosts, files=page_files(from_memory=way == "memory"))


def test_memory_is_the_default_and_static_files_the_fallback() -> None:
    assert isinstance(page_files(), PageCache)
    assert isinstance(page_files(from_memory=False), PageFiles)


def test_the_page_is_every_file_the_page_names() -> None:
    index = (STATIC / "index.html").read_text()
    named = [name for name in PAGE_FILES if f"/static/{name}" in index]
    assert "js/app.js" in named and "monitor.css" in named
    assert "vendor/d3-hierarchy.min.mjs" in named


def test_memory_and_static_files_give_the_same_bytes_and_types() -> None:
    with local_client(_app("memory")) as memory, local_client(_app("StaticFiles")) as disk:
        for path in ["/", *(f"/static/{name}" for name in PAGE_FILES), "/static/nothing.js"]:
            ours, theirs = memory.get(path), disk.get(path)
            assert ours.status_code == theirs.status_code, path
            if ours.status_code == 200:
                assert ours.content == theirs.content, path
                assert ours.headers["content-type"] == theirs.headers["content-type"], path
                assert ours.headers["cache-control"] == theirs.headers["cache-control"], path


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize("name", PAGE_FILES)
def test_each_file_is_served_with_its_bytes_type_and_etag(way: str, name: str) -> None:
    with local_client(_app(way)) as client:
        response = client.get(f"/static/{name}")
        assert response.status_code == 200
        assert response.content == (STATIC / name).read_bytes()
        suffix = "." + name.rpartition(".")[2]
        assert response.headers["content-type"] == MEDIA_TYPES[suffix]
        assert response.headers["cache-control"] == "no-cache"
        etag = response.headers["etag"]
        again = client.get(f"/static/{name}", headers={"if-none-match": etag})
        assert again.status_code == 304 and again.content == b""
        assert again.headers["etag"] == etag and again.headers["cache-control"] == "no-cache"
        assert client.head(f"/static/{name}").headers["etag"] == etag


@pytest.mark.parametrize("way", WAYS)
def test_the_page_itself_is_index_html_and_revalidates(way: str) -> None:
    with local_client(_app(way)) as client:
        page = client.get("/")
        assert page.status_code == 200
        assert page.content == (STATIC / "index.html").read_bytes()
        assert page.headers["content-type"] == "text/html; charset=utf-8"
        assert page.headers["cache-control"] == "no-cache"
        assert client.get("/", headers={"if-none-match": page.headers["etag"]}).status_code \
            == 304
        assert client.get("/", headers={"if-none-match": '"other"'}).status_code == 200


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize("path", ["/static/nothing.js", "/static/../server.py",
                                  "/static/%2e%2e/server.py", "/static/..%2fserver.py",
                                  "/static/js", "/static/", "/static//etc/passwd"])
def test_nothing_else_is_served(way: str, path: str) -> None:
    with local_client(_app(way)) as client:
        response = client.get(path)
        assert response.status_code == 404
        assert "import" not in response.text


@pytest.mark.parametrize("way", WAYS)
def test_the_host_check_guards_the_files_too(way: str) -> None:
    app = _app(way, hosts=HostPolicy(own_names=[]))
    with local_client(app, base_url="http://rebind.attacker.example:8080") as client:
        assert client.get("/static/js/app.js").status_code == 403
        assert client.get("/").status_code == 403


def _static_imports(module: str) -> set[str]:
    """Every module ``module`` (a path under the static folder) loads by static imports."""
    found: set[str] = set()
    waiting = [module]
    while waiting:
        name = waiting.pop()
        if name in found:
            continue
        found.add(name)
        text = (STATIC / name).read_text(encoding="utf-8")
        for target in re.findall(r'^import[^;]*?from\s+"([^"]+)"', text, re.M):
            waiting.append(posixpath.normpath(posixpath.join(posixpath.dirname(name), target)))
    return found


def test_every_module_the_tree_needs_is_preloaded_so_no_import_waits_on_another() -> None:
    html = (STATIC / "index.html").read_text(encoding="utf-8")
    preloaded = set(re.findall(r'<link rel="modulepreload" href="/static/([^"]+)">', html))
    needed = _static_imports("js/app.js")
    assert "js/tree_view.js" in needed and "vendor/d3-hierarchy.min.mjs" in needed
    assert needed - preloaded == set(), "imported by the page's start but not preloaded"
    assert preloaded - needed == set(), "preloaded but not needed for the first paint"
