"""The links' shared sender: changes from any thread coalesced, the newest text sent, nothing
twice, no key more often than its interval, on_change told of every change."""

from __future__ import annotations

import asyncio
import threading

from cyborg.monitor.latest_state import LatestState


class Page:
    """What the pages got, and the state the bus changes."""

    def __init__(self) -> None:
        self.state = {"a": "1", "b": "x"}
        self.got: list[tuple[str, str]] = []
        self.looked: list[str] = []

    def text_of(self, key: str) -> str | None:
        return self.state.get(key)

    def deliver(self, key: str, text: str) -> None:
        self.got.append((key, text))


def test_the_newest_text_goes_out_once_and_not_more_often_than_the_interval() -> None:
    page = Page()

    async def run() -> None:
        state = LatestState[str](0.2, page.text_of, page.deliver, page.looked.append)
        state.attach(asyncio.get_running_loop())
        threads = [threading.Thread(target=state.notify, args=("a",)) for _ in range(20)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        await asyncio.sleep(0.02)
        assert page.got == [("a", "1")], "twenty changes before the loop looked: one send"
        state.notify("a")  # nothing new: the same text is not sent again
        await asyncio.sleep(0.02)
        assert page.got == [("a", "1")]
        page.state["a"] = "2"
        state.notify("a")
        page.state["a"] = "3"  # changed again before the interval passed
        state.notify("b")  # another key has its own interval
        await asyncio.sleep(0.05)
        assert page.got == [("a", "1"), ("b", "x")], "a waits for its interval"
        await asyncio.sleep(0.25)
        assert page.got[-1] == ("a", "3"), "then the newest text, not the one of the change"
        assert state.sends == 3 and state.sent("a") == "3"
        assert page.looked.count("a") >= 3, "on_change saw every change looked at"
        state.forget("a")
        state.changed("a")
        assert page.got[-1] == ("a", "3") and state.sends == 4, "forgotten: sent again at once"
        page.state["b"] = "y"
        looked = len(page.looked)
        await asyncio.sleep(0.25)
        state.send_soon("b")
        assert page.got[-1] == ("b", "y") and len(page.looked) == looked, \
            "send_soon sends without on_change"
        state.detach()
        page.state["b"] = "z"
        state.notify("b")
        await asyncio.sleep(0.25)
        assert page.got[-1] == ("b", "y"), "detached: changes are dropped"

    asyncio.run(run())


def test_a_key_with_nothing_to_send_sends_nothing() -> None:
    page = Page()

    async def run() -> None:
        state = LatestState[str](0.0, page.text_of, page.deliver)
        state.attach(asyncio.get_running_loop())
        state.notify("missing")
        await asyncio.sleep(0.02)
        assert page.got == [] and state.sends == 0 and state.sent("missing") is None

    asyncio.run(run())
