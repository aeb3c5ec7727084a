"""The waypoint tour's sequencing, with a fake robot: one leg at a time in the order given, the
next only once the last was reached; a failed leg ends the tour with its reason; a cancelled
tour says why and cancels the leg under way; every step is told."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest

from cyborg.monitor.robot_clients import GoalEnd
from cyborg.monitor.tour import TOUR_LIMIT, Tour, Waypoint, point_text


class FakeLegs:
    """Drives legs when the test says: ``finish(end)`` ends the leg under way."""

    def __init__(self) -> None:
        self.sent: list[Waypoint] = []
        self.cancelled: list[Waypoint] = []
        self.under_way: asyncio.Future[GoalEnd] | None = None

    async def send(self, point: Waypoint) -> GoalEnd:
        assert self.under_way is None or self.under_way.done(), "one leg at a time"
        self.sent.append(point)
        self.under_way = asyncio.get_running_loop().create_future()
        try:
            return await self.under_way
        except asyncio.CancelledError:
            self.cancelled.append(point)
            raise

    async def finish(self, end: GoalEnd) -> None:
        assert self.under_way is not None and not self.under_way.done()
        self.under_way.set_result(end)
        await _idle()


async def _idle() -> None:
    for _ in range(10):
        await asyncio.sleep(0)


POINTS: list[Waypoint] = [(1.0, 2.0, None), (3.5, -1.25, 1.5707963), (0.0, 0.0, None)]
REACHED = GoalEnd("reached", "reached the goal")


def _tour(legs: FakeLegs, told: list[dict[str, Any]]) -> Tour:
    return Tour("/cyborg", POINTS, legs.send, told.append)


def test_the_points_are_driven_to_in_order_one_at_a_time() -> None:
    async def scenario() -> tuple[FakeLegs, list[dict[str, Any]], Tour]:
        legs, told = FakeLegs(), list[dict[str, Any]]()
        tour = _tour(legs, told)
        task = tour.start()
        await _idle()
        assert legs.sent == POINTS[:1], "the second leg waits for the first"
        await legs.finish(REACHED)
        assert legs.sent == POINTS[:2]
        await legs.finish(REACHED)
        await legs.finish(REACHED)
        await task
        return legs, told, tour

    legs, told, tour = asyncio.run(scenario())
    assert legs.sent == POINTS and legs.cancelled == []
    assert [(m["state"], m["leg"]) for m in told] == [
        ("running", 1), ("running", 2), ("running", 3), ("done", 3)]
    assert told[1]["message"] == "leg 2 of 3: to (3.50, -1.25) heading 90°"
    assert told[-1]["message"] == "all 3 points reached"
    assert all(m["t"] == "tour" and m["ns"] == "/cyborg" and m["legs"] == 3 for m in told)
    assert told[0]["points"] == [[1.0, 2.0, None], [3.5, -1.25, 1.5707963], [0.0, 0.0, None]]
    assert tour.over and tour.state == "done"


@pytest.mark.parametrize("outcome", ["failed", "no_path", "canceled"])
def test_a_leg_that_does_not_reach_its_point_ends_the_tour_with_its_reason(outcome: str) -> None:
    async def scenario() -> tuple[FakeLegs, list[dict[str, Any]]]:
        legs, told = FakeLegs(), list[dict[str, Any]]()
        task = _tour(legs, told).start()
        await _idle()
        await legs.finish(REACHED)
        await legs.finish(GoalEnd(outcome, "FAILED_PLAN: the way is blocked"))
        await task
        return legs, told

    legs, told = asyncio.run(scenario())
    assert legs.sent == POINTS[:2], "the third point is never sent"
    assert told[-1]["state"] == "failed" and told[-1]["leg"] == 2
    assert told[-1]["message"] == (f"leg 2 of 3 to (3.50, -1.25) heading 90°: {outcome} "
                                   "(FAILED_PLAN: the way is blocked)")


def test_a_cancelled_tour_says_why_and_cancels_the_leg_under_way() -> None:
    async def scenario() -> tuple[FakeLegs, list[dict[str, Any]], Tour]:
        legs, told = FakeLegs(), list[dict[str, Any]]()
        tour = _tour(legs, told)
        task = tour.start()
        await _idle()
        await legs.finish(REACHED)
        tour.cancel("stopped")
        with pytest.raises(asyncio.CancelledError):
            await task
        tour.cancel("again")  # a tour that is over stays as it ended
        await _idle()
        return legs, told, tour

    legs, told, tour = asyncio.run(scenario())
    assert legs.cancelled == [POINTS[1]]
    assert told[-1]["state"] == "canceled" and told[-1]["message"] == "stopped during leg 2 of 3"
    assert sum(m["state"] == "canceled" for m in told) == 1 and tour.over


def test_a_leg_that_cannot_be_sent_ends_the_tour() -> None:
    async def refused(_point: Waypoint) -> GoalEnd:
        raise RuntimeError("action /cyborg/move_to_goal: the server rejected the goal")

    told: list[dict[str, Any]] = []

    async def scenario() -> None:
        await Tour("/cyborg", POINTS, refused, told.append).start()

    asyncio.run(scenario())
    assert told[-1]["state"] == "failed"
    assert told[-1]["message"] == ("leg 1 of 3: action /cyborg/move_to_goal: the server "
                                   "rejected the goal")


@pytest.mark.parametrize("count", [0, TOUR_LIMIT + 1])
def test_a_tour_has_one_to_fifty_points(count: int) -> None:
    with pytest.raises(ValueError, match=f"a tour has 1 to {TOUR_LIMIT} points, not {count}"):
        Tour("/cyborg", [(0.0, 0.0, None)] * count, FakeLegs().send, print)


def test_points_read_as_people_write_them() -> None:
    assert point_text((1.0, -2.345, None)) == "(1.00, -2.35)"
    assert point_text((0.0, 0.0, -3.14159)) == "(0.00, 0.00) heading -180°"
