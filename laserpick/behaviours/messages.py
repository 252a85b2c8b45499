"""What the user is told: the sentences the behaviours say that more than one place shares,
and those built from what the arm met (`crowded_message`)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "MARK_MOVES",
    "NOT_HOLDING",
    "NO_BASKET_HOLD",
    "PAST_THE_OPENING",
    "TUCKING_FIRST",
    "crowded_message",
]

#: Which way (unit vector, `base` xy) a refused place mark should move, by the words the
#: refusal ends with (`crowded_message`).
MARK_MOVES = {
    "farther left": (0.0, 1.0),
    "farther right": (0.0, -1.0),
    "nearer you": (-1.0, 0.0),
    "farther from you": (1.0, 0.0),
}

#: What the user is told when the hand let go of an object partly past the basket's opening
#: (no posture held it wholly over it): no camera sees the basket, and such an object may lie
#: across both walls, where the next carry to the basket meets it.
PAST_THE_OPENING = (
    "Part of it reached past the basket's opening when the hand let go, so it may lie on"
    " the rim or beside the basket: please check before the next drop."
)

#: Why a grasp was not taken for the basket: held that way, no posture the arm can reach
#: holds the object over the basket's opening, so it would be carried there and brought back.
NO_BASKET_HOLD = "Held that way, the object could not be held over the basket."

#: The failure of a behaviour that needs the hand to hold something, when it holds nothing.
NOT_HOLDING = "The hand is not holding anything."

#: Said as the carry to the basket goes by the tucked pose, out of a narrow gap.
TUCKING_FIRST = "Tucking the object in on the way to the basket."


def crowded_message(points: np.ndarray, spot: np.ndarray) -> str:
    """What the user hears when every way down to a place `spot` (m, `base`) comes too close
    to something: on which side of the spot the `points` (N, 3; m, `base`) it came too
    close to lie, and which way a mark should move (`MARK_MOVES`), as the user sees it from
    the seat (`base` +x ahead, +y left). "Too close to something there" alone tells the user
    nothing they can see: a hand held level goes down with its wrist 22 cm to one side."""
    if len(points) == 0:
        return "The arm would come down too close to something there."
    dx, dy = np.mean(points[:, :2], axis=0) - spot[:2]
    if abs(dy) >= abs(dx):
        where, move = (
            ("to the left of", "farther right") if dy > 0 else ("to the right of", "farther left")
        )
    else:
        where, move = ("beyond", "nearer you") if dx > 0 else ("in front of", "farther from you")
    return f"The arm would come down too close to something {where} that spot: mark one {move}."
