"""The labelling web app: its session, its HTTP API, and the page in a real headless Chromium."""

from __future__ import annotations

import json
import queue
import shutil
import signal
import sqlite3
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from roughwalk.errors import InvalidArgumentError
from roughwalk.planning import (
    Foothold,
    PairSelector,
    Preference,
    PreferenceStore,
    TerrainCost,
)
from roughwalk.planning.labeling import LabelingServer, LabelingSession, StalePairError
from roughwalk.terrain import Terrain, load_terrain

SPEC = "round_rocks:seed=3,length=0.6,pad_start=0.05,pad_end=0.05"
CHROMIUM = "/usr/bin/chromium"


@pytest.fixture(scope="module")
def terrain() -> Terrain:
    return load_terrain(SPEC)


@pytest.fixture
def session(tmp_path: Path, terrain: Terrain) -> Iterator[LabelingSession]:
    store = PreferenceStore.open(tmp_path / "prefs.sqlite", create=True)
    s = LabelingSession(store, [terrain], seed=1, background=False)
    yield s
    s.close()
    store.close()


def test_session_records_skips_and_undoes(session: LabelingSession) -> None:
    first = session.state()
    assert first["count"] == 0 and not first["can_undo"] and first["model"]["n_used"] == 0
    token = first["pair"]["token"]
    state = session.label(token, "left")
    assert state["count"] == 1 and state["can_undo"]
    assert state["model"]["n_used"] == 1 and state["model"]["train_agreement"] == 1.0
    # A second press on the same pair (key repeat, another tab) records nothing.
    with pytest.raises(StalePairError):
        session.label(token, "right")
    state = session.label(state["pair"]["token"], "skip")
    assert state["count"] == 1
    shown = state["pair"]
    state = session.label(shown["token"], "equal")
    assert state["count"] == 2
    # Undo deletes the row and shows the undone pair again.
    state = session.undo()
    assert state["count"] == 1
    assert (state["pair"]["left"]["x"], state["pair"]["right"]["y"]) == (
        shown["left"]["x"],
        shown["right"]["y"],
    )
    session.undo()
    with pytest.raises(InvalidArgumentError, match="nothing to undo"):
        session.undo()
    with pytest.raises(InvalidArgumentError, match="unknown choice 'up'"):
        session.label(session.state()["pair"]["token"], "up")
    assert session.store.count() == 0


def test_patch_shows_the_ground_in_the_heading_frame(session: LabelingSession) -> None:
    cfg = session.config
    ground = session.terrains[SPEC]
    foothold = Foothold(SPEC, 0.31, 0.04, np.pi / 2)
    patch = session._patch(foothold)
    h = np.array(patch["heights"])
    assert h.shape == (cfg.patch_cells, cfg.patch_cells)
    c = cfg.patch_cells // 2
    assert h[c, c] == 0.0
    # Forward (first index) along heading π/2 is +y; left (second index) is −x.
    step = 2 * cfg.patch_half_size / (cfg.patch_cells - 1)
    z0 = ground.height([[0.31, 0.04]])[0]
    for di, dj in ((5, 0), (0, 7), (-3, -4)):
        x, y = 0.31 - dj * step, 0.04 + di * step
        assert h[c + di, c + dj] == pytest.approx(ground.height([[x, y]])[0] - z0, abs=1e-5)


def test_informative_pairs_are_those_the_model_is_least_sure_about(terrain: Terrain) -> None:
    cost = TerrainCost.load()
    selector = PairSelector([terrain], radii=cost.radii, seed=4)
    feats = cost.features_for(terrain)

    def margin(p) -> float:
        fa, fb = feats.at([p.a.xy]), feats.at([p.b.xy])
        w = cost.weights[p.leg]
        mask = w != 0
        d = ((fa - fb) / selector.scale)[0][mask]
        return float(abs((fa - fb)[0] @ w) / np.linalg.norm(d))

    proposals = [selector.propose(cost) for _ in range(200)]
    informative = [margin(p) for p in proposals if p.informative]
    random = [margin(p) for p in proposals if not p.informative]
    assert 0.6 < len(informative) / len(proposals) < 0.9
    assert np.median(informative) < 0.2 * np.median(random)
    assert {p.leg for p in proposals} == {"front", "hind"}


def test_earlier_judgements_on_missing_terrains_are_kept(tmp_path: Path, terrain: Terrain) -> None:
    path = tmp_path / "prefs.sqlite"
    gone = tmp_path / "gone.npz"
    from roughwalk.terrain.loaders import save_npz

    save_npz(terrain, gone)
    board = load_terrain(str(gone))
    with PreferenceStore.open(path, create=True) as store:
        store.add_terrain(board)
        store.add(
            Preference(Foothold(board.spec, 0.2, 0.0), Foothold(board.spec, 0.3, 0), "front", "a")
        )
    gone.unlink()
    with PreferenceStore.open(path) as store:
        s = LabelingSession(store, [terrain], background=False)
        assert len(s.unusable) == 1 and "gone.npz" in s.unusable[0]
        state = s.label(s.state()["pair"]["token"], "right")
        assert state["count"] == 2
        s.close()


def _request(url: str, body: bytes | None = None, headers: dict | None = None):
    req = urllib.request.Request(url, data=body, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, r.headers.get("Content-Type"), r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers.get("Content-Type"), e.read()


def test_http_api(session: LabelingSession) -> None:
    server = LabelingServer(session)
    server.start()
    try:
        base = server.url
        assert base.startswith("http://127.0.0.1:")
        status, kind, body = _request(base)
        assert status == 200 and kind.startswith("text/html") and b"app.js" in body
        status, kind, body = _request(base + "static/app.js")
        assert status == 200 and b"keydown" in body
        assert _request(base + "static/../labeling_server.py")[0] == 404
        status, _, body = _request(base + "api/state")
        state = json.loads(body)
        assert status == 200 and state["count"] == 0

        def post(path: str, data: dict, kind: str = "application/json"):
            return _request(base + path, json.dumps(data).encode(), {"Content-Type": kind})

        token = state["pair"]["token"]
        # Only JSON posts (a cross-site form cannot send one without CORS).
        assert post("api/label", {"token": token, "choice": "left"}, "text/plain")[0] == 400
        status, _, body = post("api/label", {"token": token, "choice": "left"})
        assert status == 200 and json.loads(body)["count"] == 1
        status, _, body = post("api/label", {"token": token, "choice": "left"})
        assert status == 409 and json.loads(body)["state"]["count"] == 1
        assert post("api/label", {"token": "x", "choice": "north"})[0] == 400
        # Requests that name another host (DNS rebinding) are refused.
        assert _request(base + "api/state", headers={"Host": "evil.example:80"})[0] == 403
        status, _, body = post("api/undo", {})
        assert status == 200 and json.loads(body)["count"] == 0
        assert post("api/undo", {})[0] == 400
        assert session.store.count() == 0
    finally:
        server.shutdown()


# --------------------------------------------------------------- browser


def _browser():
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("playwright is not installed (`pip install playwright`, in the dev extras)")
    if not Path(CHROMIUM).exists() and not shutil.which("chromium"):
        pytest.skip(
            "Debian's chromium is not installed (`apt-get install chromium`, done by "
            "`make install` when run as root); the labelling page cannot be tested"
        )
    return sync_playwright


class Server:
    """``roughwalk cost label`` in a subprocess, as a user starts it."""

    def __init__(self, store: Path) -> None:
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "roughwalk.cli.main",
                "cost",
                "label",
                "--terrain",
                SPEC,
                "--store",
                str(store),
                "--port",
                "0",
                "--seed",
                "5",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.url = self._address()

    def _address(self) -> str:
        lines: queue.Queue[str] = queue.Queue()

        def read(stream) -> None:
            for line in stream:
                lines.put(line)
            lines.put("")

        self._reader = threading.Thread(target=read, args=(self.proc.stdout,), daemon=True)
        self._reader.start()
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            try:
                line = lines.get(timeout=1.0)
            except queue.Empty:
                continue
            if not line:
                break
            if "http://" in line:
                return "http://" + line.split("http://", 1)[1].split()[0]
        _, err = self.stop(signal.SIGKILL)
        raise AssertionError(f"the labelling server did not start: {err}")

    def stop(self, sig: int) -> tuple[int, str]:
        self.proc.send_signal(sig)
        assert self.proc.stderr is not None and self.proc.stdout is not None
        self.proc.wait(timeout=30)
        err = self.proc.stderr.read()
        self._reader.join(timeout=10)
        self.proc.stderr.close()
        self.proc.stdout.close()
        return self.proc.returncode, err


def test_label_ten_pairs_by_keyboard_undo_one_restart_and_see_nine(tmp_path: Path) -> None:
    sync_playwright = _browser()
    store = tmp_path / "prefs.sqlite"
    keys = ["ArrowLeft", "ArrowRight", "ArrowLeft", "ArrowDown", "ArrowRight",
            "ArrowLeft", "a", "d", "ArrowLeft", "ArrowRight"]  # fmt: skip
    expected = {"ArrowLeft": "a", "a": "a", "ArrowRight": "b", "d": "b", "ArrowDown": "equal"}

    def count_is(page, n: int) -> None:
        page.wait_for_function(
            f"document.getElementById('count').textContent === '{n}'", timeout=20000
        )

    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=CHROMIUM if Path(CHROMIUM).exists() else shutil.which("chromium"),
            args=["--no-sandbox"],
        )
        try:
            page = browser.new_page()
            server = Server(store)
            try:
                page.goto(server.url)
                count_is(page, 0)
                assert page.locator("#leg").inner_text().lower() in ("front", "hind")
                for i, key in enumerate(keys):
                    page.keyboard.press(key)
                    count_is(page, i + 1)
                assert page.locator("#session-count").inner_text() == "10"
                page.keyboard.press("u")
                count_is(page, 9)
                page.wait_for_function(
                    "document.getElementById('agreement').textContent.includes('your way')"
                )
            finally:
                # A crash, not a polite stop: what was shown as saved must be on disk.
                server.stop(signal.SIGKILL)
            again = Server(store)
            try:
                page.goto(again.url)
                count_is(page, 9)
                assert page.locator("#session-count").inner_text() == "0"
            finally:
                code, err = again.stop(signal.SIGTERM)
            assert code == 0 and "stopped: 9 judgements" in err
        finally:
            browser.close()
    conn = sqlite3.connect(store)
    rows = conn.execute("SELECT label, leg, source FROM preferences ORDER BY id").fetchall()
    conn.close()
    assert [r[0] for r in rows] == [expected[k] for k in keys[:9]]
    assert {r[2] for r in rows} == {"human"}
    assert {r[1] for r in rows} <= {"front", "hind"}
