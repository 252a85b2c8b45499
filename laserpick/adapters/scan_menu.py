"""What the switch adapter scans, groups first then items (`GROUPS`): laser (up, down, left,
right, confirm, back), grasps (previous, next, go, back), drive (forward, reverse, left,
right, back), mode (pick and drop, pick and place, automatic grasp, manual grasp, back), and
cancel, which acts at once. Drive items act while the switch stays held after the selection
(a dead-man).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["BACK", "GROUPS", "Group", "Item"]


@dataclass(frozen=True)
class Item:
    """One scanned choice. key: `group.item`, unique; label: what is announced; action: what
    the adapter does; hold: acts while the switch is held (driving), not once."""

    key: str
    label: str
    action: str
    hold: bool = False


@dataclass(frozen=True)
class Group:
    """A group of items, or (no items) a choice that acts itself, like cancel."""

    key: str
    label: str
    items: tuple[Item, ...] = ()
    action: str | None = None

    def as_item(self) -> Item:
        assert self.action is not None
        return Item(self.key, self.label, self.action)


BACK = "back"


def _group(key: str, label: str, *items: tuple[str, str, str, bool]) -> Group:
    made = tuple(Item(f"{key}.{k}", lab, action, hold) for k, lab, action, hold in items)
    return Group(key, label, (*made, Item(f"{key}.back", "back", BACK)))


GROUPS: tuple[Group, ...] = (
    _group(
        "laser",
        "laser",
        ("up", "up", "nudge_up", False),
        ("down", "down", "nudge_down", False),
        ("left", "left", "nudge_left", False),
        ("right", "right", "nudge_right", False),
        ("confirm", "confirm", "confirm", False),
    ),
    _group(
        "grasps",
        "grasps",
        ("previous", "previous grasp", "grasp_prev", False),
        ("next", "next grasp", "grasp_next", False),
        ("go", "go", "go", False),
    ),
    _group(
        "drive",
        "drive",
        ("forward", "forward", "drive_forward", True),
        ("reverse", "reverse", "drive_reverse", True),
        ("left", "turn left", "drive_left", True),
        ("right", "turn right", "drive_right", True),
    ),
    _group(
        "mode",
        "mode",
        ("drop", "pick and drop", "mode_drop", False),
        ("place", "pick and place", "mode_place", False),
        ("auto", "automatic grasp", "select_auto", False),
        ("manual", "manual grasp", "select_manual", False),
    ),
    Group("cancel", "cancel", action="cancel"),
)
