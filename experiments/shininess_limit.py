"""How well can any method read shininess when the light's own sharpness is unknown? (docs/refinement.md)

`radar synth` draws shininess alpha ~ U(1, 196) and three spherical-Gaussian lights of sharpness lambda ~ U(10, 30).
A Phong lobe of shininess alpha is close to a spherical Gaussian of sharpness alpha, and a highlight is the light
seen through that lobe: near its peak a spherical Gaussian of sharpness s = lambda alpha / (lambda + alpha).
Suppose a method measured every seen highlight's s exactly up to a log-normal noise, and knew the priors. The best
it can answer is the posterior median of alpha (the mean absolute error's minimiser); this prints its mean
absolute error by Monte Carlo, against the best constant guess (the prior median, 48.75). The diffuse shading,
which would also depend on lambda, is left out: it is the light blurred by a cosine lobe (about 60 deg wide),
which hides the difference between 10 deg and 18 deg wide lights under any painted texture.

    .venv/bin/python -m experiments.shininess_limit
"""

from __future__ import annotations

import numpy as np

ALPHA = (1.0, 196.0)  # synth.generator
LAMBDA = (10.0, 30.0)  # synth.lighting
TRIALS = 1500
BEST_CONSTANT = (ALPHA[1] - ALPHA[0]) / 4  # mean |alpha - median| under the uniform prior


def posterior_median(observed: np.ndarray, noise: float, grid: np.ndarray, predicted: np.ndarray) -> float:
    """The posterior median of alpha (on `grid`, G) given k highlights' measured sharpness (k); predicted: G x M
    log sharpness of a highlight for every alpha of the grid and M lights' sharpness spread over their prior."""
    log_post = np.zeros_like(grid)
    for log_s in np.log(observed):
        likelihood = np.exp(-0.5 * ((log_s - predicted) / noise) ** 2).mean(axis=1)  # over lambda's prior
        log_post += np.log(likelihood + 1e-300)
    post = np.exp(log_post - log_post.max())
    cdf = np.cumsum(post) / post.sum()
    return float(grid[np.searchsorted(cdf, 0.5)])


def main() -> None:
    rng = np.random.default_rng(0)
    grid = np.linspace(*ALPHA, 391)
    lambdas = LAMBDA[0] + (np.arange(200) + 0.5) * (LAMBDA[1] - LAMBDA[0]) / 200  # quadrature over lambda's prior
    predicted = np.log(grid[:, None] * lambdas[None] / (grid[:, None] + lambdas[None]))  # G x M
    print("highlights seen | log noise | best possible mean error | x best constant (48.75)")
    for seen in (1, 2, 3):
        for noise in (0.02, 0.1, 0.2, 0.5):
            errors = []
            for _ in range(TRIALS):
                alpha, lam = rng.uniform(*ALPHA), rng.uniform(*LAMBDA, seen)
                observed = alpha * lam / (alpha + lam) * np.exp(rng.normal(0.0, noise, seen))
                errors.append(abs(posterior_median(observed, noise, grid, predicted) - alpha))
            mean = float(np.mean(errors))
            print(f"{seen} | {noise:.2f} | {mean:.1f} | {mean / BEST_CONSTANT:.2f}", flush=True)


if __name__ == "__main__":
    main()
