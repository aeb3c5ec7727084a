"""The robot commands of the map (go, go_pose, home, dock, undock, set_pose, stop, drive, tour)
through the monitor's protocol, on a fake robot: the seat rules (stop works without the seat,
the rest needs it), the tree paused before a manual goal and stopped by a stop until someone
with the seat resumes it, every page told
how a goal ended, bad fields answered with the field at fault and nothing sent, the robot's
own refusals passed on, home decided, driving clamped and a driver that leaves stopped."""

from __future__ import annotations

import asyncio
import json
from typing import Any

import pytest

from cyborg.interfaces.robot import (
    TELEOP_MAX_SPEED,
    TELEOP_MAX_TURN_RATE,
    TELEOP_TIMEOUT,
    MoveOutcome,
)
from cyborg.monitor.client import Client
from cyborg.monitor.commands import receive
from cyborg.monitor.hub import Hub
from cyborg.monitor.seat import NOT_HOLDER, VIEW_ONLY
from tests.monitor.robot_fakes import HOME, ROBOT, acting_hub, idle, of_kind, page, until

TREE = "/cyborg/bt"


async def _send(hub: Hub, client: Client, command: dict[str, Any] | str) -> dict[str, Any]:
    """Sends ``command`` as ``client`` and returns its answer (a result or an error)."""
    await receive(hub, client, command if isinstance(command, str) else json.dumps(command))
    answers = of_kind(client, "result", "error")
    assert len(answers) == 1, answers
    return answers[0]


def _enabled(hub: Hub) -> bool | None:
    return hub.sources[TREE].enabled


def test_a_goal_pauses_the_running_tree_and_every_page_hears_how_it_ended() -> None:
    hub, buses = acting_hub()

    async def scenario() -> None:
        holder, other = page(hub, 1), page(hub, 2)
        hub.seat.claim(1)
        answer = await _send(hub, holder, {"t": "go", "ns": ROBOT, "goal": "Office", "req": 3})
        assert answer["ok"] is True and answer["req"] == 3 and answer["command"] == "go"
        assert answer["paused"] == TREE and answer["goal"] == "'Office'"
        assert answer["message"] == ("/cyborg: going to 'Office'; the tree /cyborg/bt is paused "
                                     "for it")
        assert _enabled(hub) is False, "paused before the goal"
        assert of_kind(other, "manual_pause") == [{"t": "manual_pause", "tree": TREE,
                                                   "ns": ROBOT}]
        bus = buses[ROBOT]
        assert bus.calls == [("goal_names",), ("goal", "Office", None, False)]
        bus.goals[0].end(MoveOutcome.SUCCEEDED, "reached the goal")
        await idle()
        told = {"t": "robot_result", "ns": ROBOT, "command": "go", "goal": "'Office'",
                "outcome": "reached", "message": "reached the goal"}
        assert of_kind(holder, "robot_result") == [{**told, "req": 3}]
        assert of_kind(other, "robot_result") == [{**told, "req": None}]
        again = await _send(hub, holder, {"t": "go_pose", "ns": ROBOT, "pose": [4, 1.5, 3.1416]})
        assert again["ok"] is True and again["paused"] is None, "the tree was paused already"
        assert again["message"] == "/cyborg: going to (4.00, 1.50) heading 180°"
        assert bus.calls[-1] == ("goal", "", (4.0, 1.5, 3.1416), True)
        bus.goals[1].end(MoveOutcome.NO_PATH, "FAILED_PLAN: no path")
        await idle()
        assert of_kind(other, "robot_result")[0]["outcome"] == "no_path"

    asyncio.run(scenario())


def test_a_page_that_comes_later_hears_of_the_manual_pause_until_the_tree_runs_again() -> None:
    hub, _buses = acting_hub()

    async def scenario() -> None:
        holder = page(hub, 1)
        hub.seat.claim(1)
        assert (await _send(hub, holder, {"t": "go", "ns": ROBOT, "goal": "Office"}))["ok"]
        late = page(hub, 2)
        await receive(hub, late, json.dumps({"t": "hello"}))
        assert of_kind(late, "manual_pause") == [{"t": "manual_pause", "tree": TREE,
                                                  "ns": ROBOT}]
        resumed = await _send(hub, holder, {"t": "enable", "on": True, "ns": TREE})
        assert resumed["ok"], resumed
        later = page(hub, 3)
        await receive(hub, later, json.dumps({"t": "hello"}))
        assert of_kind(later, "manual_pause") == [], "the tree runs again: no banner"

    asyncio.run(scenario())


def test_stop_needs_no_seat_but_every_other_command_does() -> None:
    hub, buses = acting_hub(token="s3cret")
    commands: list[dict[str, Any]] = [
        {"t": "go", "goal": "Office"}, {"t": "go_pose", "pose": [1, 2]}, {"t": "home"},
        {"t": "dock"}, {"t": "undock"}, {"t": "set_pose", "pose": [1, 2, 0]},
        {"t": "drive", "vx": 0.2, "wz": 0}, {"t": "tour", "points": [[1, 2]]}]

    async def scenario() -> None:
        holder, other = page(hub, 1), page(hub, 2)
        viewer = page(hub, 3, may_control=False)
        hub.seat.claim(1)
        for command in commands:
            answer = await _send(hub, other, {**command, "ns": ROBOT})
            assert answer["ok"] is False and NOT_HOLDER in answer["message"], command
            answer = await _send(hub, viewer, {**command, "ns": ROBOT})
            assert answer["ok"] is False and VIEW_ONLY in answer["message"], command
        assert buses == {} and _enabled(hub) is True, "nothing reached the robot or the tree"
        stopped = await _send(hub, other, {"t": "stop", "ns": ROBOT, "req": 9})
        assert stopped == {"t": "result", "n": 9, "req": 9, "command": "stop", "ok": True,
                           "message": "/cyborg: stopped; the tree /cyborg/bt is stopped until "
                                      "someone resumes it", "paused": None, "stopped": [TREE]}
        assert buses[ROBOT].calls == [("stop",)]
        assert _enabled(hub) is False and hub.sources[TREE].stopped is True, "the tree stopped"
        refused = await _send(hub, viewer, {"t": "stop", "ns": ROBOT})
        assert refused["ok"] is False and VIEW_ONLY in refused["message"]
        assert of_kind(holder, "manual_pause") == []

    asyncio.run(scenario())


def test_a_stopped_tree_is_told_to_every_page_and_only_the_seat_resumes_it() -> None:
    hub, _buses = acting_hub()

    async def scenario() -> None:
        holder, other = page(hub, 1), page(hub, 2)
        hub.seat.claim(1)
        assert (await _send(hub, holder, {"t": "go", "ns": ROBOT, "goal": "Office"}))["paused"]
        assert (await _send(hub, other, {"t": "stop", "ns": ROBOT}))["ok"]
        late = page(hub, 3)
        await receive(hub, late, json.dumps({"t": "hello"}))
        assert of_kind(late, "manual_pause") == [], "stopped now, not paused for the goal"
        trees = of_kind(late, "robots")[0]["robots"]
        assert [(tree["ns"], tree["stopped"]) for tree in trees] == [(TREE, True)]
        refused = await _send(hub, other, {"t": "enable", "on": True, "ns": TREE})
        assert refused["ok"] is False and NOT_HOLDER in refused["message"]
        assert hub.sources[TREE].stopped is True
        assert (await _send(hub, holder, {"t": "enable", "on": True, "ns": TREE}))["ok"]
        assert hub.sources[TREE].stopped is False and _enabled(hub) is True

    asyncio.run(scenario())


def test_in_a_fleet_stop_stops_the_robot_acted_on_and_its_tree_alone() -> None:
    """As MobileEyes and RViz's Nav2 panel act on one robot: the others drive on."""
    hub, buses = acting_hub(robots=("/robot1", "/robot2", "/robot3"))

    async def scenario() -> None:
        answer = await _send(hub, page(hub, 1), {"t": "stop", "ns": "/robot2"})
        assert answer["ok"] is True and answer["stopped"] == ["/robot2/bt"], answer
        assert set(buses) == {"/robot2"} and buses["/robot2"].calls == [("stop",)]
        assert {tree: (source.enabled, source.stopped) for tree, source in hub.sources.items()
                } == {"/robot1/bt": (True, False), "/robot2/bt": (False, True),
                      "/robot3/bt": (True, False)}

    asyncio.run(scenario())


BAD_FIELDS: list[tuple[dict[str, Any], str, str]] = [
    ({"t": "go", "goal": "Office"}, "ns", "name the robot in ns (such as /cyborg)"),
    ({"t": "go", "ns": "/nope", "goal": "Office"}, "ns",
     "no robot /nope on the bus (robots: /cyborg)"),
    ({"t": "dock", "ns": "/**"}, "ns", "'/**' is not a namespace"),
    ({"t": "go", "ns": ROBOT, "goal": "Nowhere"}, "goal",
     "no goal 'Nowhere' on the map of /cyborg (goals: 'Office', 'Library')"),
    ({"t": "go", "ns": ROBOT, "goal": ""}, "goal", "goal: the name of one of the map's goals"),
    ({"t": "go", "ns": ROBOT, "goal": ["Office"]}, "goal", "not ['Office']"),
    ({"t": "go_pose", "ns": ROBOT, "pose": [1]}, "pose",
     "pose: [x, y] or [x, y, θ] in metres and radians, not [1]"),
    ({"t": "go_pose", "ns": ROBOT, "pose": [1, "a"]}, "pose", "pose[1] is 'a', not a finite"),
    ({"t": "go_pose", "ns": ROBOT, "pose": [1, None, 0]}, "pose", "pose[1] is None"),
    ({"t": "go_pose", "ns": ROBOT, "pose": [1, True]}, "pose", "pose[1] is True"),
    ({"t": "go_pose", "ns": ROBOT, "pose": [1e9, 0]}, "pose",
     "pose: [1000000000.0, 0] is more than 10 km from the map's origin"),
    ({"t": "set_pose", "ns": ROBOT, "pose": "here"}, "pose", "not 'here'"),
    ({"t": "drive", "ns": ROBOT, "vx": "fast", "wz": 0}, "vx", "vx is 'fast', not a finite"),
    ({"t": "drive", "ns": ROBOT, "vx": 0.1}, "wz", "wz is None"),
    ({"t": "tour", "ns": ROBOT, "points": []}, "points", "points: a list of 1 to 50"),
    ({"t": "tour", "ns": ROBOT, "points": [[0, 0]] * 51}, "points", "points: a list of 1 to 50"),
    ({"t": "tour", "ns": ROBOT, "points": [[0, 0], [1]]}, "points[1]", "points[1]: [x, y]"),
    # numbers JSON carries but a float does not hold, or no heading is: an OverflowError each
    ({"t": "go_pose", "ns": ROBOT, "pose": [0, 0, 1e308]}, "pose", "pose[2] is 1e+308, not a "
     "heading in radians"),
    ({"t": "go_pose", "ns": ROBOT, "pose": [10**400, 0]}, "pose", "pose[0] is 1000"),
    ({"t": "drive", "ns": ROBOT, "vx": 10**400, "wz": 0}, "vx", "not a finite number"),
    ({"t": "tour", "ns": ROBOT, "points": [[0, 0, -1e300]]}, "points[0]", "not a heading"),
]


@pytest.mark.parametrize(("command", "field", "text"), BAD_FIELDS,
                         ids=[f"{c['t']}-{f}-{i}" for i, (c, f, _t) in enumerate(BAD_FIELDS)])
def test_a_bad_field_is_refused_naming_it_and_nothing_is_sent(
        command: dict[str, Any], field: str, text: str) -> None:
    hub, buses = acting_hub()

    async def scenario() -> dict[str, Any]:
        client = page(hub, 1)
        hub.seat.claim(1)
        return await _send(hub, client, {**command, "req": 5})

    answer = asyncio.run(scenario())
    assert answer["t"] == "result" and answer["ok"] is False and answer["req"] == 5
    assert answer["field"] == field and text in answer["message"]
    assert answer["message"].startswith(f"message 1 ({command['t']}), field {field}: ")
    assert _enabled(hub) is True, "a refused command does not pause the tree"
    goals = [call for bus in buses.values() for call in bus.calls if call[0] != "goal_names"]
    assert goals == [], "nothing reached the robot"


def test_a_nan_never_reaches_the_command() -> None:
    hub, buses = acting_hub()

    async def scenario() -> dict[str, Any]:
        client = page(hub, 1)
        hub.seat.claim(1)
        return await _send(hub, client, '{"t": "go_pose", "ns": "/cyborg", "pose": [NaN, 0]}')

    answer = asyncio.run(scenario())
    assert answer["t"] == "error" and "NaN" in answer["message"]
    assert answer["message"].startswith("message 1")
    assert buses == {} and _enabled(hub) is True


def test_the_robots_own_refusal_is_the_answer() -> None:
    hub, buses = acting_hub()

    async def scenario() -> list[dict[str, Any]]:
        client = page(hub, 1)
        hub.seat.claim(1)
        await _send(hub, client, {"t": "stop", "ns": ROBOT})
        buses[ROBOT].refuse = {"set_pose": "(90.00, 3.00) is off the map",
                               "dock": "campus.map has no Dock", "undock": "not docked"}
        return [await _send(hub, client, command) for command in (
            {"t": "set_pose", "ns": ROBOT, "pose": [90, 3, 0]}, {"t": "dock", "ns": ROBOT},
            {"t": "undock", "ns": ROBOT})]

    placed, docked, undocked = asyncio.run(scenario())
    assert placed["ok"] is False and placed["field"] == "pose"
    assert placed["message"].endswith("/cyborg/set_pose refused: (90.00, 3.00) is off the map")
    assert docked["ok"] is False and docked["message"].endswith(
        "/cyborg/dock refused: campus.map has no Dock")
    assert undocked["ok"] is False and undocked["message"].endswith(
        "/cyborg/undock refused: not docked")


def test_home_is_the_maps_home_else_its_goal_named_home() -> None:
    async def home(objects: tuple[dict[str, Any], ...], names: list[str]
                   ) -> tuple[dict[str, Any], list[tuple[Any, ...]]]:
        hub, buses = acting_hub(objects=objects)
        client = page(hub, 1)
        hub.seat.claim(1)
        await _send(hub, client, {"t": "stop", "ns": ROBOT})
        buses[ROBOT].names = names
        answer = await _send(hub, client, {"t": "home", "ns": ROBOT})
        return answer, buses[ROBOT].calls

    answer, calls = asyncio.run(home((HOME,), ["Office"]))
    assert answer["ok"] is True and answer["message"].startswith(
        "/cyborg: going to home Home (2.00, 3.00) heading 90°")
    assert calls[-1] == ("goal", "", (2.0, 3.0, 1.5708), True), "its pose, facing its heading"
    answer, calls = asyncio.run(home((), ["Office", "HOME"]))
    assert answer["ok"] is True and calls[-1] == ("goal", "HOME", None, False)
    answer, calls = asyncio.run(home((), ["Office"]))
    assert answer["ok"] is False and answer["message"].endswith(
        "the map of /cyborg has no home (no RobotHome, no goal named home)")
    assert all(call[0] != "goal" for call in calls)


def test_set_pose_without_a_heading_keeps_the_robots() -> None:
    hub, buses = acting_hub()

    async def scenario() -> dict[str, Any]:
        client = page(hub, 1)
        hub.seat.claim(1)
        return await _send(hub, client, {"t": "set_pose", "ns": ROBOT, "pose": [4, 5]})

    answer = asyncio.run(scenario())
    assert answer["ok"] is True and answer["message"] == "/cyborg: at (4.00, 5.00)"
    assert buses[ROBOT].calls == [("set_pose", 4.0, 5.0, 0.5)], "the heading it has (0.5)"
    assert _enabled(hub) is True, "relocalising does not pause the tree"


def test_driving_is_clamped_and_a_driver_that_leaves_is_stopped_once() -> None:
    hub, buses = acting_hub()

    async def scenario() -> None:
        driver, bystander = page(hub, 1), page(hub, 2)
        hub.seat.claim(1)
        await receive(hub, driver, json.dumps({"t": "drive", "ns": ROBOT, "vx": 3, "wz": -7}))
        assert of_kind(driver, "result") == [], "no answer for each drive command"
        assert _enabled(hub) is False, "driving pauses the tree"
        answer = await _send(hub, driver, {"t": "drive", "ns": ROBOT, "vx": -0.2, "wz": 0.4,
                                           "req": 2})
        assert answer["ok"] is True and answer["message"] == ("/cyborg: driving at -0.20 m/s, "
                                                              "0.40 rad/s")
        bus = buses[ROBOT]
        assert bus.calls == [("drive", TELEOP_MAX_SPEED, -TELEOP_MAX_TURN_RATE),
                             ("drive", -0.2, 0.4)]
        hub.disconnect(bystander)
        assert bus.calls[-1] == ("drive", -0.2, 0.4), "a page that never drove stops nothing"
        hub.disconnect(driver)
        assert bus.calls[-1] == ("drive", 0.0, 0.0), "the driver left: one zero twist"
        late = page(hub, 3)
        hub.seat.claim(3, force=True)
        await receive(hub, late, json.dumps({"t": "drive", "ns": ROBOT, "vx": 0.1, "wz": 0}))
        await asyncio.sleep(TELEOP_TIMEOUT + 0.05)
        hub.disconnect(late)
        assert bus.calls[-1] == ("drive", 0.1, 0.0), \
            "a page that drove longer ago than the deadman sends no zero (it would end a goal)"

    asyncio.run(scenario())


def test_a_stop_ends_a_drive_in_progress_until_the_driver_lets_go() -> None:
    """A key or the joystick still held on the driver's page must not drive the robot on 100 ms
    after another page's STOP."""
    hub, buses = acting_hub()

    async def scenario() -> None:
        driver, other = page(hub, 1), page(hub, 2)
        hub.seat.claim(1)
        await receive(hub, driver, json.dumps({"t": "drive", "ns": ROBOT, "vx": 0.3, "wz": 0}))
        assert (await _send(hub, other, {"t": "stop", "ns": ROBOT}))["ok"]
        bus = buses[ROBOT]
        calls = len(bus.calls)
        held = await _send(hub, driver, {"t": "drive", "ns": ROBOT, "vx": 0.3, "wz": 0})
        assert held["ok"] is False and held["command"] == "drive"
        assert "/cyborg was stopped while you drove it: let go, then drive again" in \
            held["message"]
        assert len(bus.calls) == calls, "nothing reached the robot"
        await receive(hub, driver, json.dumps({"t": "drive", "ns": ROBOT, "vx": 0, "wz": 0}))
        again = await _send(hub, driver, {"t": "drive", "ns": ROBOT, "vx": 0.3, "wz": 0,
                                          "req": 5})
        assert again["ok"] is True and bus.calls[-2:] == [("drive", 0.0, 0.0),
                                                          ("drive", 0.3, 0.0)]
        assert (await _send(hub, driver, {"t": "stop", "ns": ROBOT}))["ok"]
        own = await _send(hub, driver, {"t": "drive", "ns": ROBOT, "vx": 0.2, "wz": 0, "req": 6})
        assert own["ok"] is True, "the page that stops lets go of its own drive"

    asyncio.run(scenario())


def test_stop_ends_a_tour_and_a_new_goal_replaces_one() -> None:
    hub, buses = acting_hub()

    async def scenario() -> None:
        client = page(hub, 1)
        hub.seat.claim(1)
        answer = await _send(hub, client, {"t": "tour", "ns": ROBOT,
                                           "points": [[1, 2], [3, 4, 0]]})
        assert answer["ok"] is True and answer["paused"] == TREE
        assert answer["message"] == ("/cyborg: a tour of 2 points; the tree /cyborg/bt is "
                                     "paused for it")
        bus = buses[ROBOT]
        await until(lambda: bus.goals, "the first leg")
        assert bus.calls[-1] == ("goal", "", (1.0, 2.0, 0.0), False)
        bus.goals[0].end(MoveOutcome.SUCCEEDED, "reached the goal")
        await until(lambda: len(bus.goals) == 2, "the second leg")
        assert bus.calls[-1] == ("goal", "", (3.0, 4.0, 0.0), True)
        stopped = await _send(hub, client, {"t": "stop", "ns": ROBOT})
        assert stopped["ok"] is True
        await idle()
        tours = of_kind(client, "tour")
        assert [(m["state"], m["leg"]) for m in tours] == [("running", 1), ("running", 2),
                                                           ("canceled", 2)]
        assert tours[-1]["message"] == "stopped during leg 2 of 2"
        assert bus.goals[1].cancelled, "the leg's goal is cancelled"
        await _send(hub, client, {"t": "tour", "ns": ROBOT, "points": [[5, 5]]})
        await until(lambda: len(bus.goals) == 3, "the new tour's leg")
        await _send(hub, client, {"t": "go", "ns": ROBOT, "goal": "Library"})
        await idle()
        assert of_kind(client, "tour")[-1]["message"] == ("replaced by a new goal during leg 1 "
                                                          "of 1")

    asyncio.run(scenario())


def test_the_clients_of_a_robot_that_left_are_withdrawn() -> None:
    hub, buses = acting_hub()

    async def scenario() -> None:
        client = page(hub, 1)
        hub.seat.claim(1)
        await _send(hub, client, {"t": "stop", "ns": ROBOT})
        hub.robot_hub.robots["/robot2"] = hub.robot_hub.robots.pop(ROBOT)
        await _send(hub, client, {"t": "stop", "ns": "/robot2"})

    asyncio.run(scenario())
    assert buses[ROBOT].calls == [("stop",), ("destroy",)]
    assert buses["/robot2"].calls == [("stop",)]
