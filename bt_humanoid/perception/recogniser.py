"""The learned recogniser: which of a world's objects a region of the image is, from its RGB-D crop.

A small convolutional network (three conv blocks and two dense layers, about
170 k parameters) takes a region's crop and its size in metres
(``crops.py``) and scores each of the world's objects, plus "none" (a part
of the furniture, a fragment, something it was not trained on). It is trained
on scenes rendered from the simulator (``bt_humanoid/training/``); its folder
holds the weights, the class names and the recipe that made them.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from bt_humanoid.errors import UserError
from bt_humanoid.perception.crops import CHANNELS, CROP, FEATURES

NONE = "none"  # the class of regions that are none of the world's objects
WEIGHTS = "weights.pt"
RECIPE = "recipe.json"
FEATURE_SCALE = (10.0, 10.0, 0.5)  # metres to about unit range: height and width (tenths of a m), distance (2 m)


class RecogniserNet(nn.Module):
    """Crop (B, CHANNELS, CROP, CROP) and features (B, FEATURES) → class scores (B, classes)."""

    def __init__(self, classes: int) -> None:
        super().__init__()

        def block(into: int, out: int) -> list[nn.Module]:
            return [nn.Conv2d(into, out, 3, padding=1), nn.BatchNorm2d(out), nn.ReLU(), nn.MaxPool2d(2)]

        self.conv = nn.Sequential(*block(CHANNELS, 16), *block(16, 32), *block(32, 64))  # 40 → 20 → 10 → 5
        flat = 64 * (CROP // 8) ** 2
        self.head = nn.Sequential(nn.Linear(flat + FEATURES, 96), nn.ReLU(), nn.Dropout(0.2), nn.Linear(96, classes))
        self.register_buffer("feature_scale", torch.tensor(FEATURE_SCALE, dtype=torch.float32))

    def forward(self, crops: torch.Tensor, features: torch.Tensor) -> torch.Tensor:
        seen = self.conv(crops).flatten(1)
        return self.head(torch.cat([seen, features * self.feature_scale], dim=1))


@dataclass
class Judgement:
    label: str  # an object of the world, or NONE
    confidence: float  # the network's probability for it


class Recogniser:
    """A trained RecogniserNet with its class names, ready to judge crops."""

    def __init__(self, net: RecogniserNet, classes: list[str], recipe: dict) -> None:
        self.net = net.eval()
        self.classes = classes
        self.recipe = recipe

    @classmethod
    def load(cls, folder: Path) -> Recogniser:
        """Read ``folder``'s weights and recipe (written by ``save``)."""
        if not (folder / WEIGHTS).is_file() or not (folder / RECIPE).is_file():
            raise UserError(
                f"no trained detector in {folder}",
                hint=f"it needs {WEIGHTS} and {RECIPE}; train one with python -m bt_humanoid.training.detector",
            )
        recipe = json.loads((folder / RECIPE).read_text())
        classes = list(recipe["classes"])
        net = RecogniserNet(len(classes))
        net.load_state_dict(torch.load(folder / WEIGHTS, map_location="cpu", weights_only=True))
        return cls(net, classes, recipe)

    def save(self, folder: Path) -> None:
        folder.mkdir(parents=True, exist_ok=True)
        torch.save(self.net.state_dict(), folder / WEIGHTS)
        (folder / RECIPE).write_text(json.dumps({**self.recipe, "classes": self.classes}, indent=2) + "\n")

    def judge(self, crops: np.ndarray, features: np.ndarray) -> list[Judgement]:
        """One judgement per crop (crops: (N, CHANNELS, CROP, CROP), features: (N, FEATURES))."""
        if len(crops) == 0:
            return []
        with torch.inference_mode():
            scores = self.net(torch.from_numpy(crops), torch.from_numpy(features))
            probabilities = torch.softmax(scores, dim=1)
            confidence, best = probabilities.max(dim=1)
        return [Judgement(self.classes[int(b)], float(c)) for b, c in zip(best, confidence, strict=True)]
