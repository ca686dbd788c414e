"""Write the kitchen's product labels as PNG textures (worlds/kitchen/textures/).

Cans, bottles and bags of one shape are told apart by their look, as in a real
kitchen: a colour, a printed name and a mark. The labels are drawn here with
OpenCV so anyone can change or add one; the output is the same every run
(tests/test_kitchen_world.py checks the committed files match).

    python scripts/kitchen_textures.py            # rewrite worlds/kitchen/textures/*.png
    python scripts/kitchen_textures.py --check    # exit 1 if a committed texture differs
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

FOLDER = Path(__file__).resolve().parents[1] / "worlds" / "kitchen" / "textures"
WRAP = (128, 256)  # rows, cols: wrapped once round a can or bottle
FACE = (128, 128)  # on every face of a box
FONT = cv2.FONT_HERSHEY_DUPLEX

Colour = tuple[int, int, int]  # RGB


def _canvas(shape: tuple[int, int], colour: Colour) -> np.ndarray:
    image = np.empty((*shape, 3), np.uint8)
    image[:] = colour
    return image


def _text(image: np.ndarray, text: str, colour: Colour, row: float, scale: float = 1.0, thickness: int = 2) -> None:
    """Centred text at a fraction of the height, repeated round a wrapped label so every side shows it."""
    (width, height), _ = cv2.getTextSize(text, FONT, scale, thickness)
    repeats = 2 if image.shape[1] > image.shape[0] else 1
    for k in range(repeats):
        centre = (k + 0.5) * image.shape[1] / repeats
        origin = (int(centre - width / 2), int(row * image.shape[0] + height / 2))
        cv2.putText(image, text, origin, FONT, scale, colour, thickness, cv2.LINE_AA)


def _band(image: np.ndarray, top: float, bottom: float, colour: Colour) -> None:
    image[int(top * image.shape[0]) : int(bottom * image.shape[0])] = colour


def _wave(image: np.ndarray, row: float, colour: Colour, amplitude: float = 8, thickness: int = 6) -> None:
    cols = np.arange(image.shape[1])
    rows = row * image.shape[0] + amplitude * np.sin(cols * 4 * np.pi / image.shape[1])
    points = np.stack([cols, rows], axis=1).astype(np.int32)
    cv2.polylines(image, [points], False, colour, thickness, cv2.LINE_AA)


def _dots(image: np.ndarray, colour: Colour, count: int, radius: int, seed: int) -> None:
    """Splashes of fruit colour, at spots fixed by ``seed``."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        centre = (int(rng.integers(0, image.shape[1])), int(rng.integers(0, image.shape[0])))
        cv2.circle(image, centre, int(rng.integers(radius // 2, radius + 1)), colour, -1, cv2.LINE_AA)


def _discs(image: np.ndarray, colour: Colour, radius: int, row: float = 0.5) -> None:
    for k in range(2):
        cv2.circle(image, (int((k + 0.5) * image.shape[1] / 2), int(row * image.shape[0])), radius, colour, -1)


def coke() -> np.ndarray:
    image = _canvas(WRAP, (200, 16, 30))
    _wave(image, 0.72, (255, 255, 255))
    _text(image, "Coca-Cola", (255, 255, 255), 0.4, 0.75)
    return image


def pepsi() -> np.ndarray:
    image = _canvas(WRAP, (10, 50, 150))
    _discs(image, (255, 255, 255), 26, 0.45)
    for k in range(2):
        centre = (int((k + 0.5) * WRAP[1] / 2), int(0.45 * WRAP[0]))
        cv2.ellipse(image, centre, (26, 26), 0, 180, 360, (220, 20, 40), -1)
    _text(image, "pepsi", (255, 255, 255), 0.82, 0.8)
    return image


def seven_up() -> np.ndarray:
    image = _canvas(WRAP, (0, 140, 60))
    _discs(image, (225, 30, 40), 14, 0.3)
    _text(image, "7UP", (255, 255, 255), 0.62, 1.3, 3)
    return image


def red_bull() -> np.ndarray:
    image = _canvas(WRAP, (190, 192, 200))
    for col in range(0, WRAP[1], 32):  # blue and silver checks
        for row in range(0, WRAP[0], 32):
            if (col // 32 + row // 32) % 2 == 0:
                image[row : row + 32, col : col + 32] = (25, 45, 120)
    _band(image, 0.35, 0.65, (25, 45, 120))
    _discs(image, (240, 200, 20), 12, 0.5)
    _text(image, "Red Bull", (220, 30, 40), 0.5, 0.6)
    return image


def lime_soda() -> np.ndarray:
    image = _canvas(WRAP, (236, 236, 230))
    _dots(image, (120, 200, 40), 14, 14, seed=1)
    _text(image, "LIME", (20, 120, 40), 0.5, 1.0)
    return image


def grapefruit_soda() -> np.ndarray:
    image = _canvas(WRAP, (236, 236, 230))
    _dots(image, (240, 100, 110), 14, 14, seed=2)
    _text(image, "GRAPEFRUIT", (230, 90, 40), 0.5, 0.55)
    return image


def tea() -> np.ndarray:
    image = _canvas(WRAP, (140, 70, 15))  # the tea through the plastic
    _band(image, 0.35, 0.7, (240, 210, 60))
    _text(image, "ICED TEA", (40, 110, 40), 0.52, 0.7)
    return image


def water() -> np.ndarray:
    image = _canvas(WRAP, (170, 205, 240))
    _band(image, 0.4, 0.65, (20, 70, 180))
    _text(image, "WATER", (255, 255, 255), 0.52, 0.7)
    return image


def jalapeno_chips() -> np.ndarray:
    image = _canvas(FACE, (25, 95, 45))
    cv2.ellipse(image, (64, 80), (34, 12), -20, 0, 360, (200, 30, 30), -1, cv2.LINE_AA)  # a red pepper
    _text(image, "JALAPENO", (250, 220, 40), 0.25, 0.5)
    return image


def multigrain_chips() -> np.ndarray:
    image = _canvas(FACE, (175, 115, 50))
    _dots(image, (230, 200, 140), 30, 5, seed=3)  # grains
    _text(image, "MULTI", (90, 40, 10), 0.35, 0.8)
    _text(image, "GRAIN", (90, 40, 10), 0.65, 0.8)
    return image


def rice_chips() -> np.ndarray:
    image = _canvas(FACE, (235, 205, 60))
    _band(image, 0.4, 0.62, (200, 40, 30))
    _text(image, "RICE", (255, 255, 255), 0.51, 0.8)
    return image


def blue_chips() -> np.ndarray:
    image = _canvas(FACE, (40, 95, 205))
    _band(image, 0.7, 0.85, (250, 250, 250))
    _text(image, "CHIPS", (250, 250, 250), 0.4, 0.8)
    return image


def kettle_chips() -> np.ndarray:
    image = _canvas(FACE, (28, 28, 30))
    _band(image, 0.55, 0.8, (235, 120, 20))
    _text(image, "KETTLE", (235, 120, 20), 0.3, 0.7)
    return image


def energy_bar() -> np.ndarray:
    image = _canvas(FACE, (30, 30, 32))
    _band(image, 0.15, 0.3, (200, 40, 60))
    _text(image, "RXBAR", (250, 250, 250), 0.6, 0.8)
    return image


def apple() -> np.ndarray:
    image = _canvas(FACE, (185, 25, 25))
    _dots(image, (120, 170, 40), 10, 10, seed=4)
    return image


def sponge() -> np.ndarray:
    image = _canvas(FACE, (245, 215, 60))
    _band(image, 0.0, 0.3, (40, 140, 60))  # the green scrub side
    _dots(image, (225, 190, 40), 40, 3, seed=5)  # pores
    return image


LABELS: dict[str, Callable[[], np.ndarray]] = {
    "coke": coke,
    "pepsi": pepsi,
    "7up": seven_up,
    "red_bull": red_bull,
    "lime_soda": lime_soda,
    "grapefruit_soda": grapefruit_soda,
    "tea": tea,
    "water": water,
    "jalapeno_chips": jalapeno_chips,
    "multigrain_chips": multigrain_chips,
    "rice_chips": rice_chips,
    "blue_chips": blue_chips,
    "kettle_chips": kettle_chips,
    "energy_bar": energy_bar,
    "apple": apple,
    "sponge": sponge,
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with the committed files; write nothing")
    args = parser.parse_args(argv)
    FOLDER.mkdir(parents=True, exist_ok=True)
    differ = []
    for name, draw in LABELS.items():
        path = FOLDER / f"{name}.png"
        image = draw()[..., ::-1]  # OpenCV writes BGR
        if args.check:
            committed = cv2.imread(str(path))
            if committed is None or not np.array_equal(committed, image):
                differ.append(path.name)
        else:
            cv2.imwrite(str(path), image)
    if differ:
        print(f"textures differ from what the script draws: {', '.join(differ)}", file=sys.stderr)
        return 1
    print(f"{len(LABELS)} textures {'match' if args.check else 'written to ' + str(FOLDER)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
