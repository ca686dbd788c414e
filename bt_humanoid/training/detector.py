"""Train the learned recogniser of a world's objects on views rendered from the simulator.

    python -m bt_humanoid.training.detector --world kitchen            # the committed weights (10-20 min)
    python -m bt_humanoid.training.detector --views 40 --epochs 1 --out /tmp/d   # a quick check that it runs

The recipe: random views (``views.py``) from the seed's training stream; every
region the run-time detector would judge (``learned_detector.candidates``) is
cropped exactly as at run time (``crops.py``) and labelled by a segmentation
render — the object that shows in most of its pixels, or none when no object
fills half of it. Segmentation is for training only: at run time the network
sees the RGB-D frame alone. The network (``recogniser.py``) is trained with
Adam and mild brightness jitter, then judged on views from the seed's own
validation stream. Weights and the recipe (seed, counts, accuracy) go to the
world's detector folder. CPU only; the same seed gives the same accuracy.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from bt_humanoid.perception.crops import region_crop, region_features
from bt_humanoid.perception.detector import Region
from bt_humanoid.perception.learned_detector import candidates
from bt_humanoid.perception.recogniser import NONE, Recogniser, RecogniserNet
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.training.views import ViewMaker

TRAIN_STREAM, VALIDATION_STREAM, BENCHMARK_STREAM = 0, 1, 2  # seed streams: no view is in two of them
OWN_SHARE = 0.5  # share of a region's pixels one object must show for the region to be that object


@dataclass
class Dataset:
    crops: np.ndarray  # (N, 5, 40, 40) float16
    features: np.ndarray  # (N, 3) float32
    labels: np.ndarray  # (N,) int64: index into the class list

    def __len__(self) -> int:
        return len(self.labels)


def view_rng(seed: int, stream: int, index: int) -> np.random.Generator:
    """The generator of one view: views of different streams never coincide."""
    return np.random.default_rng(np.random.SeedSequence([seed, stream, index]))


def render_dataset(maker: ViewMaker, classes: list[str], views: int, seed: int, stream: int) -> Dataset:
    """Crops and labels of every candidate region of ``views`` random views."""
    crops, features, labels = [], [], []
    index_of = {name: i for i, name in enumerate(classes)}
    started = time.perf_counter()
    for index in range(views):
        maker.arrange(view_rng(seed, stream, index))
        frame, shown = maker.capture()
        for region in candidates(frame, maker.surfaces):
            crops.append(region_crop(frame, region).astype(np.float16))
            features.append(region_features(region, frame.position))
            labels.append(index_of[region_label(region, shown, maker)])
        if (index + 1) % max(1, views // 10) == 0:
            elapsed = time.perf_counter() - started
            print(f"  rendered {index + 1}/{views} views, {len(labels)} regions ({elapsed:.0f} s)", flush=True)
    if not labels:
        return Dataset(np.zeros((0, 5, 40, 40), np.float16), np.zeros((0, 3), np.float32), np.zeros(0, np.int64))
    return Dataset(np.stack(crops), np.stack(features).astype(np.float32), np.array(labels, dtype=np.int64))


def region_label(region: Region, shown: np.ndarray, maker: ViewMaker) -> str:
    """The object that shows in most of the region's pixels, or none (clutter, furniture, no one object)."""
    instances = shown[region.rows, region.cols]
    instances = instances[instances >= 0]
    if len(instances) == 0:
        return NONE
    values, counts = np.unique(instances, return_counts=True)
    best = int(np.argmax(counts))
    instance = maker.instances[int(values[best])]
    if counts[best] < OWN_SHARE * len(region.rows) or instance.clutter:
        return NONE
    return instance.name


def train(data: Dataset, classes: list[str], epochs: int, seed: int) -> RecogniserNet:
    """A RecogniserNet fitted to ``data``; deterministic for a seed."""
    torch.manual_seed(seed)
    generator = torch.Generator().manual_seed(seed)
    net = RecogniserNet(len(classes))
    optimiser = torch.optim.Adam(net.parameters(), lr=2e-3, weight_decay=1e-4)
    steps = epochs * math.ceil(len(data) / 128)
    schedule = torch.optim.lr_scheduler.OneCycleLR(optimiser, max_lr=3e-3, total_steps=max(steps, 1))
    crops = torch.from_numpy(data.crops)
    features = torch.from_numpy(data.features)
    labels = torch.from_numpy(data.labels)
    loss_of = nn.CrossEntropyLoss(label_smoothing=0.05)
    for epoch in range(epochs):
        net.train()
        started, total, right = time.perf_counter(), 0.0, 0
        for batch in torch.randperm(len(data), generator=generator).split(128):
            x = crops[batch].float()
            bright = 0.8 + 0.4 * torch.rand(len(batch), 1, 1, 1, generator=generator)  # brightness jitter
            x[:, :3] = (x[:, :3] * bright).clamp(0, 1)
            scores = net(x, features[batch])
            loss = loss_of(scores, labels[batch])
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            schedule.step()
            total += float(loss.detach()) * len(batch)
            right += int((scores.argmax(1) == labels[batch]).sum())
        print(
            f"  epoch {epoch + 1}/{epochs}: loss {total / len(data):.3f}, training accuracy {right / len(data):.1%} "
            f"({time.perf_counter() - started:.0f} s)",
            flush=True,
        )
    return net.eval()


def accuracy(recogniser: Recogniser, data: Dataset) -> dict[str, float]:
    """Share of regions whose class the network names: all of them, and those that are objects."""
    judged = recogniser.judge(data.crops.astype(np.float32), data.features)
    predicted = np.array([recogniser.classes.index(j.label) for j in judged])
    none = recogniser.classes.index(NONE)
    objects = data.labels != none
    return {
        "accuracy": float(np.mean(predicted == data.labels)) if len(data) else math.nan,
        "object_accuracy": float(np.mean(predicted[objects] == data.labels[objects])) if objects.any() else math.nan,
        "regions": len(data),
        "object_regions": int(objects.sum()),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="kitchen")
    parser.add_argument("--views", type=int, default=6000, help="training views (default 6000)")
    parser.add_argument("--validation-views", type=int, default=600)
    parser.add_argument("--epochs", type=int, default=16)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="folder for weights and recipe (default: the world's detector/)")
    args = parser.parse_args(argv)
    world = load_world_config(args.world)
    out = args.out or world.detector_path
    if out is None:
        print(f"world '{args.world}' names no detector folder; give --out", file=sys.stderr)
        return 2
    started = time.perf_counter()
    maker = ViewMaker(args.world)
    classes = [*maker.objects, NONE]
    print(f"training the {args.world} detector: {len(classes) - 1} objects, seed {args.seed}", flush=True)
    print(f"rendering {args.views} training views", flush=True)
    data = render_dataset(maker, classes, args.views, args.seed, TRAIN_STREAM)
    print(f"rendering {args.validation_views} validation views", flush=True)
    validation = render_dataset(maker, classes, args.validation_views, args.seed, VALIDATION_STREAM)
    maker.close()
    print(f"training on {len(data)} regions, {args.epochs} epochs", flush=True)
    net = train(data, classes, args.epochs, args.seed)
    recipe = {
        "world": args.world,
        "seed": args.seed,
        "views": args.views,
        "validation_views": args.validation_views,
        "epochs": args.epochs,
        "training_regions": len(data),
        "torch": torch.__version__,
        "command": "python -m bt_humanoid.training.detector " + " ".join(argv if argv is not None else sys.argv[1:]),
    }
    recogniser = Recogniser(net, classes, recipe)
    scores = accuracy(recogniser, validation)
    recogniser.recipe |= {"validation": scores, "train_minutes": round((time.perf_counter() - started) / 60, 1)}
    recogniser.save(out)
    print(
        f"validation: {scores['accuracy']:.1%} of {scores['regions']} regions, "
        f"{scores['object_accuracy']:.1%} of {scores['object_regions']} objects; saved to {out}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
