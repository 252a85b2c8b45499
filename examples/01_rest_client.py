"""A REST client fetches an object: take control, aim, confirm, wait for grasps, Go, wait.

Everything goes through the public API (`laserpick.client.Client`, plain JSON over HTTP and
the events websocket), as a switch adapter, a phone app or your own script would. Start a
server first, then run this against it:

    laserpick serve                                  # the simulated isolation scene
    python examples/01_rest_client.py --url http://127.0.0.1:8000

`--point X Y Z` aims at a point (m, in the scooter's `base` frame: x forward, y left, z up).
Without it, the script asks a simulated server where an object is (`GET /sim/objects`,
simulator truth a real robot does not offer; `--object NAME`, or the first) and aims at it.
The pick ends with the object in the basket; `--no-go` stops at the grasps (a recorded
server cannot move).
"""

from __future__ import annotations

import argparse
import sys

from laserpick.client import ApiError, Client


def target(c: Client, point: list[float] | None, name: str | None) -> list[float]:
    """Where to aim (m, `base`): the point given, or the middle of a simulated scene's object
    (`name`, or the first)."""
    if point is not None:
        return point
    try:
        objects = c.get("/sim/objects")
    except ApiError:
        sys.exit("this server is not simulated: give --point X Y Z")
    chosen = [o for o in objects if name in (None, o["name"])]
    if not chosen:
        sys.exit(f"no object {name!r}; the scene has {', '.join(o['name'] for o in objects)}")
    print(f"aiming at {chosen[0]['name']} ({chosen[0]['model']})")
    return chosen[0]["center_base"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="http://127.0.0.1:8000", help="the server")
    parser.add_argument("--point", type=float, nargs=3, metavar=("X", "Y", "Z"))
    parser.add_argument(
        "--object", help="a simulated scene's object to aim at (default: the first)"
    )
    parser.add_argument("--no-go", action="store_true", help="stop once the grasps are ready")
    parser.add_argument("--timeout", type=float, default=180.0, help="s to wait for each step")
    args = parser.parse_args()

    with Client(args.url, name="example 01") as c:  # takes the control lease, heartbeats
        state = c.state()
        if state["estopped"]:
            sys.exit("the e-stop is latched; reset it first (POST /api/v1/stop/reset)")
        c.post("/laser/aim", {"point": target(c, args.point, args.object)})
        c.post("/laser/confirm")  # both beams: the robot looks, segments, finds grasps
        state = c.wait_for(lambda s: not s["busy"] and s["state"] != "marked", args.timeout)
        print(f"{state['state']}: {state['message']}")
        if state["state"] != "grasps_ready":
            return 1
        if args.no_go:
            return 0
        c.post("/execute")  # Go: pick, carry to the basket, drop, stow
        # The job is running once the POST returns; when it ends the state says how: idle
        # after a drop, or still holding when a halt or a failure left the object in the hand.
        state = c.wait_for(lambda s: not s["busy"], args.timeout)
        print(f"{state['state']}: {state['message']}")
        return 0 if state["failure"] is None else 1


if __name__ == "__main__":
    sys.exit(main())
