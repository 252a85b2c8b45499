"""The household object library: simple, physically plausible models of everyday objects.

The categories follow the papers' object sets: the ALS-ranked household objects of EL-E
(000, section 5.2: phone, pill, remote, bottles, cups, utensils, toothbrush, wallet, keys,
glasses case, ...), Jeeves' ten objects (003, section V: soda cans, a chip can, a cleaner
bottle, tea boxes, a vitamin bottle, a stuffed doll) and the UR5 scooter's tabletop set
(004, section 8). Sizes are typical retail sizes; every object fits an 85 mm two-finger
gripper in at least one orientation and weighs at most 1 kg.
"""

from __future__ import annotations

from laserpick.robot.sim.objects.groups import TRANSPARENT_ALPHA
from laserpick.robot.sim.objects.object_model import ObjectModel, Part
from laserpick.robot.sim.objects.shapes import (
    X_AXIS,
    banana_parts,
    bowl_parts,
    box_part,
    cylinder_part,
    make_object,
    mug_parts,
    stuffed_toy_parts,
)

#: Widest object the 85 mm gripper takes with some margin (m).
GRIPPABLE_WIDTH = 0.075
#: Heaviest object in the library (kg).
MAX_OBJECT_MASS = 1.0

_RED = (0.8, 0.1, 0.1, 1.0)
_WHITE = (0.92, 0.92, 0.9, 1.0)
_BLACK = (0.08, 0.08, 0.08, 1.0)
_STEEL = (0.75, 0.76, 0.78, 1.0)
_CLEAR = (0.7, 0.85, 0.95, TRANSPARENT_ALPHA)


def _drinks() -> list[ObjectModel]:
    """Cans and bottles (004, 003: soda cans, chip can, a cleaner bottle)."""
    return [
        make_object("soda_can", "can", [cylinder_part(0.033, 0.122)], 0.37, 0.6, _RED),
        make_object("tin_can", "can", [cylinder_part(0.037, 0.105)], 0.42, 0.5, _STEEL, "specular"),
        make_object(
            "chip_can",
            "can",
            [
                cylinder_part(0.0375, 0.23),
                cylinder_part(0.0375, 0.01, z0=0.23, rgba=(0.9, 0.6, 0.1, 1)),
            ],
            0.2,
            0.6,
            (0.8, 0.05, 0.05, 1),
        ),
        make_object(
            "water_bottle",
            "bottle",
            [
                cylinder_part(0.032, 0.17),
                cylinder_part(0.02, 0.02, z0=0.17),
                cylinder_part(0.014, 0.015, z0=0.19),
                cylinder_part(0.015, 0.012, z0=0.205, rgba=(0.2, 0.4, 0.9, 1)),
            ],
            0.52,
            0.5,
            _CLEAR,
            "transparent",
        ),
        make_object(
            "juice_bottle",
            "bottle",
            [
                cylinder_part(0.034, 0.16),
                cylinder_part(0.022, 0.025, z0=0.16),
                cylinder_part(0.02, 0.015, z0=0.185),
            ],
            0.55,
            0.6,
            (0.95, 0.55, 0.1, 1),
        ),
        make_object(
            "spray_bottle",
            "bottle",
            [
                box_part(0.035, 0.024, 0.085),  # the oval-ish body, like 003's cleaner
                cylinder_part(0.014, 0.03, z0=0.17),
                box_part(0.03, 0.013, 0.018, x=0.012, z0=0.2),  # trigger head
                box_part(0.006, 0.008, 0.018, x=0.02, z0=0.165),  # trigger
                cylinder_part(0.005, 0.01, x=0.045, z0=0.212, quat=X_AXIS),  # nozzle
            ],
            0.6,
            0.6,
            (0.2, 0.6, 0.9, 1),
        ),
    ]


def _medicine() -> list[ObjectModel]:
    """Pill bottles, a pill and a medicine box (000 section 5.2)."""
    return [
        make_object(
            "pill_bottle",
            "medicine",
            [
                cylinder_part(0.021, 0.07, rgba=(0.9, 0.5, 0.1, 1)),
                cylinder_part(0.023, 0.016, z0=0.07),
            ],
            0.06,
            0.6,
            _WHITE,
        ),
        make_object(
            "vitamin_bottle",
            "medicine",
            [
                box_part(0.018, 0.03, 0.05),
                cylinder_part(0.03, 0.1, x=0.018),
                cylinder_part(0.03, 0.1, x=-0.018),
                cylinder_part(0.022, 0.02, z0=0.1),
            ],
            0.25,
            0.6,
            (0.95, 0.85, 0.3, 1),
        ),
        make_object(
            "pill",
            "medicine",
            [Part("capsule", (0.004, 0.0015), (0, 0, 0.004), X_AXIS)],
            0.0006,
            0.5,
            _WHITE,
        ),
        make_object("medicine_box", "medicine", [box_part(0.05, 0.025, 0.015)], 0.04, 0.6, _WHITE),
    ]


def _boxes_and_food() -> list[ObjectModel]:
    """Boxes (003's tea boxes), a cup of yogurt, a spice jar and fruit."""
    return [
        make_object(
            "cereal_box", "box", [box_part(0.03, 0.095, 0.125)], 0.3, 0.6, (0.9, 0.75, 0.2, 1)
        ),
        make_object(
            "tea_box", "box", [box_part(0.035, 0.065, 0.04)], 0.1, 0.6, (0.2, 0.5, 0.25, 1)
        ),
        make_object(
            "soap_box", "box", [box_part(0.045, 0.03, 0.0175)], 0.12, 0.5, (0.6, 0.8, 0.95, 1)
        ),
        make_object(
            "yogurt_cup", "food", [cylinder_part(0.035, 0.07)], 0.15, 0.6, (0.95, 0.95, 0.85, 1)
        ),
        make_object(
            "spice_jar",
            "food",
            [
                cylinder_part(0.022, 0.09, rgba=(0.55, 0.3, 0.1, 1)),
                cylinder_part(0.023, 0.015, z0=0.09),
            ],
            0.12,
            0.6,
            _RED,
        ),
        make_object(
            "apple",
            "food",
            [Part("ellipsoid", (0.037, 0.037, 0.033), (0, 0, 0.033))],
            0.18,
            0.7,
            (0.75, 0.1, 0.1, 1),
        ),
        make_object("banana", "food", banana_parts(), 0.12, 0.7, (0.95, 0.85, 0.2, 1)),
    ]


def _dishes_and_utensils() -> list[ObjectModel]:
    """A mug, cups, a bowl, a fork and a spoon."""
    return [
        make_object("mug", "dish", mug_parts(), 0.3, 0.6, (0.2, 0.35, 0.7, 1)),
        make_object(
            "plastic_cup", "dish", [cylinder_part(0.035, 0.09)], 0.02, 0.5, (0.9, 0.3, 0.5, 1)
        ),
        make_object(
            "glass_cup", "dish", [cylinder_part(0.035, 0.1)], 0.2, 0.5, _CLEAR, "transparent"
        ),
        make_object("bowl", "dish", bowl_parts(), 0.25, 0.6, (0.95, 0.95, 0.95, 1)),
        make_object(
            "fork",
            "utensil",
            [box_part(0.055, 0.006, 0.0015, x=-0.035), box_part(0.025, 0.011, 0.0015, x=0.045)],
            0.04,
            0.4,
            _STEEL,
            "specular",
        ),
        make_object(
            "spoon",
            "utensil",
            [
                box_part(0.055, 0.006, 0.0015, x=-0.035),
                Part("ellipsoid", (0.028, 0.018, 0.006), (0.045, 0, 0.006)),
            ],
            0.035,
            0.4,
            _STEEL,
            "specular",
        ),
    ]


def _phones_and_hygiene() -> list[ObjectModel]:
    """Phones, a remote and hygiene items (000 section 5.2)."""
    return [
        make_object(
            "cordless_phone",
            "phone",
            [box_part(0.075, 0.024, 0.014), box_part(0.02, 0.022, 0.004, x=0.05, z0=0.028)],
            0.14,
            0.7,
            (0.15, 0.15, 0.18, 1),
        ),
        make_object("cell_phone", "phone", [box_part(0.073, 0.0355, 0.004)], 0.17, 0.5, _BLACK),
        make_object(
            "tv_remote", "remote", [box_part(0.09, 0.025, 0.011)], 0.12, 0.7, (0.2, 0.2, 0.22, 1)
        ),
        make_object(
            "toothbrush",
            "hygiene",
            [box_part(0.07, 0.0065, 0.0075), box_part(0.0125, 0.006, 0.0085, x=0.0825)],
            0.02,
            0.6,
            (0.3, 0.7, 0.9, 1),
        ),
        make_object("toothpaste", "hygiene", [box_part(0.09, 0.022, 0.015)], 0.12, 0.6, _WHITE),
        make_object(
            "tissue_packet", "hygiene", [box_part(0.053, 0.027, 0.0125)], 0.02, 0.8, _WHITE
        ),
    ]


def _personal_items() -> list[ObjectModel]:
    """A mouse, a marker, a glasses case, a wallet and keys (000 section 5.2)."""
    return [
        make_object(
            "computer_mouse",
            "electronics",
            [box_part(0.05, 0.028, 0.006), Part("ellipsoid", (0.052, 0.03, 0.018), (0, 0, 0.018))],
            0.09,
            0.6,
            (0.3, 0.3, 0.32, 1),
        ),
        make_object(
            "marker",
            "stationery",
            [
                Part("cylinder", (0.009, 0.055), (-0.01, 0, 0.009), X_AXIS),
                Part("cylinder", (0.009, 0.02), (0.065, 0, 0.009), X_AXIS, rgba=_BLACK),
            ],
            0.015,
            0.5,
            _WHITE,
        ),
        make_object(
            "glasses_case", "personal", [box_part(0.08, 0.032, 0.02)], 0.08, 0.7, (0.4, 0.2, 0.1, 1)
        ),
        make_object(
            "wallet", "personal", [box_part(0.055, 0.036, 0.01)], 0.1, 0.8, (0.35, 0.2, 0.1, 1)
        ),
        make_object(
            "keys",
            "personal",
            [box_part(0.03, 0.015, 0.006, rgba=_BLACK), box_part(0.025, 0.01, 0.0015, x=0.055)],
            0.05,
            0.5,
            _STEEL,
        ),
    ]


def _toys() -> list[ObjectModel]:
    """Stuffed toys (003's stuffed doll, 004) and a ball."""
    return [
        make_object("stuffed_toy", "toy", stuffed_toy_parts(1.0), 0.15, 0.9, (0.6, 0.45, 0.3, 1)),
        make_object("small_plush", "toy", stuffed_toy_parts(0.7), 0.06, 0.9, (0.9, 0.6, 0.7, 1)),
        make_object(
            "ball", "toy", [Part("sphere", (0.034,), (0, 0, 0.034))], 0.058, 0.8, (0.8, 0.9, 0.2, 1)
        ),
    ]


#: The library's families, in the library's order.
_FAMILIES = (
    _drinks,
    _medicine,
    _boxes_and_food,
    _dishes_and_utensils,
    _phones_and_hygiene,
    _personal_items,
    _toys,
)


def _build_library() -> dict[str, ObjectModel]:
    objs = [obj for family in _FAMILIES for obj in family()]
    lib = {o.name: o for o in objs}
    if len(lib) != len(objs):
        raise ValueError("duplicate object names in the library")
    return lib


#: The built-in household objects by name.
LIBRARY: dict[str, ObjectModel] = _build_library()


def opaque_names() -> list[str]:
    """Names of the opaque library objects, sorted: the default pool for random placement."""
    return sorted(n for n, o in LIBRARY.items() if o.optical == "opaque")
