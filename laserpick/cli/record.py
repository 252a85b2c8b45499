"""`laserpick record`: a recording (docs/recording.md) of a scene simulated headless."""

from __future__ import annotations

import argparse
from pathlib import Path

from laserpick.cli.common import EXIT_USAGE, rendering_problem, say

__all__ = ["add_record_parser", "cmd_record"]


def add_record_parser(sub: argparse._SubParsersAction) -> None:
    """`laserpick record OUT --scene NAME`: a recording from a scene simulated headless."""
    record = sub.add_parser(
        "record",
        help="capture a simulated scene into a recording (serve it with serve --recorded)",
        description="Load a scene headless, let it settle, optionally confirm the laser on an"
        " object, capture once, and write the recording (format: docs/recording.md).",
    )
    record.add_argument("out", type=Path, metavar="OUT", help="a new (or empty) directory")
    record.add_argument("--scene", required=True, help="a built-in scene name or a scene YAML path")
    record.add_argument("--seed", type=int, help="the scene's random placement seed")
    record.add_argument(
        "--aim-at-object",
        metavar="INSTANCE",
        help="confirm the laser (both beams) on this object before capturing",
    )
    record.set_defaults(func=cmd_record)


def cmd_record(args: argparse.Namespace) -> int:
    """Simulate a scene headless, let it settle, confirm the laser on an object if asked,
    capture once, and write the recording to `args.out`."""
    out: Path = args.out
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        say(f"{out} already exists and is not an empty directory; choose another", err=True)
        return EXIT_USAGE
    problem = rendering_problem()
    if problem is not None:
        say(problem, err=True)
        return EXIT_USAGE

    from laserpick.robot.sim.scenes import load_scene

    try:
        scene = load_scene(args.scene, seed=args.seed)
    except Exception as exc:
        say(f"cannot load scene {args.scene!r}: {exc}", err=True)
        return EXIT_USAGE
    instances = [p.instance for p in scene.placements]
    target = args.aim_at_object
    if target is not None and target not in instances:
        say(
            f"scene {scene.name!r} has no object {target!r}; it has: {', '.join(instances)}",
            err=True,
        )
        return EXIT_USAGE

    from laserpick.pipeline.cloud import fuse
    from laserpick.robot.recording import Hint, Recording, capture_from, write_recording
    from laserpick.robot.sim.truth import capture

    say(f"simulating scene {scene.name!r} headless and letting it settle", err=True)
    captured = capture(scene)
    try:
        hint = None
        if target is not None:
            top = captured.visible_top(fuse(captured.frames), target)
            if top is None:
                say(f"no camera sees {target!r}: the laser cannot be aimed at it", err=True)
                return 1
            captured.robot.laser.aim_at(top)
            captured.robot.laser.confirm()
            hint = Hint(target, top)
            where = ", ".join(f"{v:.3f}" for v in top)
            say(f"laser confirmed on {target!r}, its top at ({where}) m in base", err=True)
        say("capturing", err=True)
        seed = "the scene's seed" if args.seed is None else f"seed {args.seed}"
        recording = Recording(
            (capture_from(captured.robot, hint),),
            captured.robot.projector(),
            source=f"laserpick record: scene {scene.name!r}, {seed}",
        )
        write_recording(out, recording)
    finally:
        captured.close()
    say(f"wrote {out}: 1 capture from {len(recording.cameras)} cameras", err=True)
    return 0
