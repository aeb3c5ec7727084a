"""A robot's battery over a recording: the charge, and when it was docked or charging.

From ``battery_status`` (:class:`~cyborg.bus.msgs.cyborg_msgs.msg.BatteryStatus`, latched,
about once a second of the robot's clock): the charge in percent at each message's log time,
and the periods in which the robot was charging (``charging``) and docked (``dock_state`` is
``DOCKED``), each as (start, end) in log time. A period still open when the recording ends,
ends with it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from cyborg.interfaces.robot import DockState
from cyborg.report.recording import Stamped


@dataclass
class BatteryHistory:
    """The charge over time and the charging and docked periods (log times, ns)."""

    charge: list[tuple[int, float]] = field(default_factory=list)
    charging: list[tuple[int, int]] = field(default_factory=list)
    docked: list[tuple[int, int]] = field(default_factory=list)

    @property
    def lowest(self) -> float | None:
        """The lowest charge seen, percent; None without messages."""
        return min((value for _, value in self.charge), default=None)


def battery_history(messages: list[Stamped], end: int) -> BatteryHistory:
    """The history of one robot's ``battery_status`` messages; ``end`` closes open periods."""
    history = BatteryHistory()
    charging_since: int | None = None
    docked_since: int | None = None
    for item in messages:
        message, when = item.message, item.log_time
        history.charge.append((when, float(message.charge_percent)))
        charging, docked = bool(message.charging), message.dock_state == DockState.DOCKED
        if charging and charging_since is None:
            charging_since = when
        elif not charging and charging_since is not None:
            history.charging.append((charging_since, when))
            charging_since = None
        if docked and docked_since is None:
            docked_since = when
        elif not docked and docked_since is not None:
            history.docked.append((docked_since, when))
            docked_since = None
    if charging_since is not None:
        history.charging.append((charging_since, max(end, charging_since)))
    if docked_since is not None:
        history.docked.append((docked_since, max(end, docked_since)))
    return history
