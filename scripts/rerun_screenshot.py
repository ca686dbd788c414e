"""Screenshot a Rerun recording in a headless viewer (for docs/rerun.md).

    python scripts/rerun_screenshot.py RUN.rrd OUT.png [--at SECONDS] [--size 1600x900]

Needs rerun-sdk and a graphics stack the viewer can draw with without a display: a GPU driver, or Mesa's
software Vulkan (lavapipe: ``apt-get install mesa-vulkan-drivers``). Uses Rerun's experimental ViewerClient
(rerun-sdk 0.41), which spawns ``rerun --headless`` on a local port.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording", type=Path)
    parser.add_argument("output", type=Path)
    parser.add_argument("--at", type=float, help="simulation time to show (default: the end)")
    parser.add_argument("--port", type=int, default=9899)
    args = parser.parse_args()
    from rerun.experimental import ViewerClient

    viewer = ViewerClient.spawn(headless=True, port=args.port, hide_welcome_screen=True)
    try:
        viewer.open(str(args.recording.resolve()))
        deadline = time.monotonic() + 60
        while viewer.get_state().loading and time.monotonic() < deadline:
            time.sleep(0.5)
        state = viewer.get_state()
        recording = next(r for r in state.recordings)
        timeline = next(t for t in recording.timelines if t.name == "sim_time")
        at = timeline.end if args.at is None else round(args.at * 1e9)
        viewer.set_time("sim_time", duration=at / 1e9, play_state="paused")
        time.sleep(3)  # let images decode and views settle
        viewer.save_screenshot(str(args.output.resolve()))
    finally:
        viewer.quit()


if __name__ == "__main__":
    main()
