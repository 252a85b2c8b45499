"""Our targets for the bench runs, checked by `report.check_targets` beside the papers'
figures (`papers`)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Target:
    """A target of ours, checked by `report.check_targets`.

    metric: "grasp_success_rate", "detect_success_rate", "task_success_rate" (>= threshold),
    "attempt_total_s" (mean attempt time, < threshold, s), or "wrong_object_manual_vs_auto"
    (manual per-attempt wrong-object rate <= threshold x the automatic one).
    protocols: the protocols it applies to; empty: all.
    """

    label: str
    metric: str
    op: str
    threshold: float
    protocols: tuple[str, ...] = ()

    def applies(self, protocol: str) -> bool:
        return not self.protocols or protocol in self.protocols


#: Our targets.
TARGETS: tuple[Target, ...] = (
    Target(
        "Grasp success per attempt (004: 93.8 % per detected attempt)",
        "grasp_success_rate",
        ">=",
        0.94,
        ("isolation",),
    ),
    Target("Detection success (004: 92.3 %)", "detect_success_rate", ">=", 0.92, ("isolation",)),
    Target("Task success (004: 96.0 %)", "task_success_rate", ">=", 0.96, ("in-situ",)),
    Target("Task success (004: 96.4 %)", "task_success_rate", ">=", 0.96, ("pick-place",)),
    Target(
        "Manual wrong-object rate at most half the automatic (004: 8 % against 26 %)",
        "wrong_object_manual_vs_auto",
        "<=",
        0.5,
        ("selection",),
    ),
    Target("Mean attempt time", "attempt_total_s", "<", 20.0),
)


def targets(protocol: str) -> tuple[Target, ...]:
    """The targets that apply to a protocol."""
    return tuple(t for t in TARGETS if t.applies(protocol))
