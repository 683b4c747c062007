"""The lowest F_dist that N endpoints on a sphere can have.

F_dist is the mean of 200 / (d + 5) over pairs of different endpoints (Poncin, section
4.4.2). Spreads N points on a sphere of radius R by gradient descent from a Fibonacci
lattice and from random starts, and compares with random points. Used in docs/automata.md.

    python scripts/experiments/fdist_floor.py
"""

import numpy as np


def f_dist(points: np.ndarray) -> float:
    d = np.linalg.norm(points[:, None] - points[None], axis=-1)
    return float((200 / (d + 5))[np.triu_indices(len(points), 1)].mean())


def on_sphere(points: np.ndarray, radius: float) -> np.ndarray:
    return radius * points / np.linalg.norm(points, axis=1)[:, None]


def fibonacci(n: int, radius: float) -> np.ndarray:
    i = np.arange(n) + 0.5
    polar, azimuth = np.arccos(1 - 2 * i / n), np.pi * (1 + 5**0.5) * i
    unit = np.stack(
        [np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar), np.cos(polar)], 1
    )
    return radius * unit


def spread(points: np.ndarray, radius: float, steps: int = 5000, rate: float = 50.0) -> float:
    n = len(points)
    for _ in range(steps):
        diff = points[:, None] - points[None]
        d = np.linalg.norm(diff, axis=-1) + np.eye(n)
        grad = (-200 / (d + 5) ** 2 / d)[..., None] * diff
        grad[np.arange(n), np.arange(n)] = 0
        points = on_sphere(points - rate * grad.sum(1), radius)
    return f_dist(points)


def main() -> None:
    rng = np.random.default_rng(1)
    for n in (30, 31):
        for radius in (150.0, 165.0):
            starts = [fibonacci(n, radius)]
            starts += [on_sphere(rng.normal(size=(n, 3)), radius) for _ in range(5)]
            best = min(spread(p, radius) for p in starts)
            print(f"{n} endpoints, radius {radius:.0f}: lowest F_dist {best:.3f}")
    random = [f_dist(on_sphere(rng.normal(size=(30, 3)), 150.0)) for _ in range(2000)]
    print(f"30 random endpoints, radius 150: mean F_dist {np.mean(random):.3f}")


if __name__ == "__main__":
    main()
