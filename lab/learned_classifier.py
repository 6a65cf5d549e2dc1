"""Would a learned classifier read the windows' bars better than the ratio thresholds?  Tuning maps only.

Reads the default pipeline's tuning maps (``lab/tune_accuracy.py``'s store; the
reporting cases are closed to that script) and counts each region's holes three ways,
each map read by a model fitted without it (4 folds by position, as
``experiments.tuning.cross_validated``):

* ``ratio``: the shipped rule, (q_1, tau_1) refitted per fold: beta_1 = #{k : S_k > ln tau_1};
* ``logistic`` and ``boosted``: a per-rank model (scikit-learn ``LogisticRegression`` on
  standardised features, ``HistGradientBoostingClassifier``) of P(the k-th bar is a
  hole), trained on the one-region maps whose beta_0 is right (rank k is a hole when
  k <= the true beta_1); a region's count is the c maximising
  sum_{k <= c} ln p_k + sum_{k > c} ln(1 - p_k) over its first RANKS ranks.

Per rank k, from the region's W windows (every feature a ratio or a count, so none has
a unit): the pooled scores S_k at q = 0.5, 0.7 and 0.9 (``ratio.pooled_scores``); the
spread of the windows' k-th scores; the gaps S_{k-1} - S_k and S_k - S_{k+1}; the mean
over windows of ln(birth / l_0.5) and ln(death / l_0.5) of the window's k-th longest
bar; the log mean number of bars per window; ln W.  The rank itself is left out: it
would learn the suite's mix of hole counts, not what a bar looks like.

Prints exact (beta_0, beta_1) counts overall and per cell for each; ``--shuffles N``
repeats the comparison with the maps in N seeded random orders (other folds), and
``--reading contact-trace`` reads the tuning cases mapped as contact traces.

    python lab/learned_classifier.py [--store tuning.duckdb] [--shuffles 4] [--reading contact-trace]
"""

from __future__ import annotations

import argparse

import numpy as np
from sklearn.ensemble import HistGradientBoostingClassifier
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from calibration import default_maps
from swarmtopo.experiments.accuracy import CELLS
from tuning import cross_validated_exact
from swarmtopo.readers.base import longest_bars
from swarmtopo.readers.ratio import LOG_RATIO_CAP, noise_length, score_matrix

RANKS = 6
"""Ranks per region a learned model reads (the suite's arenas have at most 3 holes per region)."""
FOLDS = 4
MODELS = {
    "logistic": lambda: make_pipeline(StandardScaler(), LogisticRegression(C=1.0, max_iter=2000)),
    "boosted": lambda: HistGradientBoostingClassifier(max_iter=200, learning_rate=0.05, max_leaf_nodes=15,
                                                      min_samples_leaf=20, random_state=0),
}


def rank_features(windows) -> np.ndarray:
    """(RANKS, features) of one region's windows (module docstring)."""
    # each window's scores, RANKS + 1 ranks (a missing rank scores 0), at each q
    scores = {q: np.pad(m, ((0, 0), (0, max(0, RANKS + 1 - m.shape[1]))))[:, :RANKS + 1]
              for q, m in ((q, score_matrix(windows, 1, q)) for q in (0.5, 0.7, 0.9))}
    pooled = {q: m.mean(axis=0) for q, m in scores.items()}  # ratio.pooled_scores
    ends = np.zeros((len(windows), RANKS, 2))  # ln(birth / l_q), ln(death / l_q); no bar: 0
    for w, diagram in enumerate(windows):
        lq = noise_length(diagram, 1, 0.5)
        if lq > 0:
            bars = np.asarray(diagram[1])[longest_bars(diagram, 1, RANKS)]
            with np.errstate(divide="ignore"):
                ends[w, :len(bars)] = np.clip(np.log(bars / lq), -LOG_RATIO_CAP, LOG_RATIO_CAP)
    s = pooled[0.5]
    previous = np.r_[LOG_RATIO_CAP, s[:RANKS - 1]]
    n_bars = np.log(np.mean([max(len(d[1]), 1) for d in windows]))
    return np.column_stack([pooled[0.5][:RANKS], pooled[0.7][:RANKS], pooled[0.9][:RANKS],
                            scores[0.5][:, :RANKS].std(axis=0),
                            previous - s[:RANKS], s[:RANKS] - s[1:RANKS + 1], ends.mean(axis=0),
                            np.full(RANKS, n_bars), np.full(RANKS, np.log(len(windows)))])


def joint_count(p: np.ndarray) -> int:
    """argmax_c sum_{k <= c} ln p_k + sum_{k > c} ln(1 - p_k)."""
    yes, no = np.log(np.clip(p, 1e-9, 1.0)), np.log(np.clip(1 - p, 1e-9, 1.0))
    return int(np.argmax([yes[:c].sum() + no[c:].sum() for c in range(len(p) + 1)]))


def learned_right(maps, features, make_model) -> np.ndarray:
    """Whether each map is exactly right when read by ``make_model()`` fitted on the other folds."""
    fold = np.arange(len(maps)) % FOLDS
    right = np.zeros(len(maps), bool)
    for k in range(FOLDS):
        train = [i for i in np.flatnonzero(fold != k)
                 if len(maps[i].regions) == 1 and maps[i].est_betti0 == maps[i].true_betti0]
        X = np.vstack([features[i][0] for i in train])
        y = np.concatenate([np.arange(RANKS) < maps[i].true_betti1 for i in train])
        model = make_model().fit(X, y)
        for i in np.flatnonzero(fold == k):
            m = maps[i]
            count = sum(joint_count(model.predict_proba(f)[:, 1]) for f in features[i])
            right[i] = m.est_betti0 == m.true_betti0 and count == m.true_betti1
    return right


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="tuning.duckdb", help="a store written by lab/tune_accuracy.py")
    parser.add_argument("--shuffles", type=int, default=0, help="also compare with the maps in this many random orders")
    parser.add_argument("--reading", choices=("log", "contact-trace"), default="log",
                        help="the maps of whole log folders (default) or of their contact traces")
    args = parser.parse_args()
    maps = default_maps(args.store, args.reading)
    features = [[rank_features(region) for region in m.regions] for m in maps]
    print(f"{args.store}: {len(maps)} default-pipeline tuning maps reading the {args.reading}; exact "
          f"(beta_0, beta_1), {FOLDS}-fold cross-validated; per cell: " + ", ".join(c.name for c in CELLS))
    for shuffle in range(args.shuffles + 1):
        order = np.arange(len(maps)) if shuffle == 0 else np.random.default_rng(shuffle).permutation(len(maps))
        ordered, ordered_features = [maps[i] for i in order], [features[i] for i in order]
        print("job order:" if shuffle == 0 else f"random order {shuffle}:")
        for name, right in [("ratio", cross_validated_exact(ordered, folds=FOLDS))] + [
                (n, learned_right(ordered, ordered_features, make)) for n, make in MODELS.items()]:
            per_cell = [int(sum(ok for m, ok in zip(ordered, right) if m.cell == c.name)) for c in CELLS]
            print(f"  {name}: {int(right.sum())}/{len(maps)}; per cell {per_cell}", flush=True)


if __name__ == "__main__":
    main()
