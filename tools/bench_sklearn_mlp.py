"""Train scikit-learn's MLPRegressor with the protocol of benches/mlp.rs (same rows, same
training splits, 3-4-1 logistic network, plain per-sample SGD at the same learning rate, no
momentum, no regularisation, same epochs, the same min-max scaling) and compare its time with
criterion's measurement of ours: `python tools/bench_sklearn_mlp.py target/bench-data/mlp target/criterion`.
"""

import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.neural_network import MLPRegressor


def main() -> None:
    data_dir, criterion = Path(sys.argv[1]), Path(sys.argv[2])
    proto = json.loads((data_dir / "protocol.json").read_text())
    d = np.loadtxt(data_dir / "data.csv", delimiter=",", skiprows=1)
    x, y = d[:, :3], d[:, 3]
    n = len(y)

    def run():
        errors = []
        for s, train in enumerate(proto["splits"]):
            train = np.array(train)
            test = np.setdiff1d(np.arange(n), train)
            lo, hi = x[train].min(0), x[train].max(0)
            ylo, yhi = y[train].min(), y[train].max()
            scale = lambda v: (v - lo) / np.where(hi > lo, hi - lo, 1.0)
            m = MLPRegressor(
                hidden_layer_sizes=(proto["hidden"],),
                activation="logistic",
                solver="sgd",
                learning_rate="constant",
                learning_rate_init=proto["learning_rate"],
                momentum=0.0,
                nesterovs_momentum=False,
                batch_size=1,
                alpha=0.0,
                max_iter=proto["epochs"],
                tol=0.0,
                n_iter_no_change=proto["epochs"] + 1,
                shuffle=True,
                random_state=s,
            )
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ConvergenceWarning)
                m.fit(scale(x[train]), (y[train] - ylo) / (yhi - ylo))
            pred = m.predict(scale(x[test])) * (yhi - ylo) + ylo
            errors.append(float(np.abs(pred - y[test]).mean()))
        return errors

    times = []
    for _ in range(1):  # one run: per-sample SGD in Python takes over a minute
        t0 = time.perf_counter()
        errors = run()
        times.append(time.perf_counter() - t0)
    sk = float(np.median(times))

    def ours(name):
        est = json.loads((criterion / "mlp" / name / "new" / "estimates.json").read_text())
        return est["mean"]["point_estimate"] * 1e-9

    seq, par = ours("ten_splits_sequential"), ours("ten_splits_rayon")
    print(f"10 splits x {proto['epochs']} epochs, 3-{proto['hidden']}-1, lr {proto['learning_rate']}, {n} rows (30 % train):")
    print(f"  scikit-learn MLPRegressor (sgd, batch 1)  {sk:8.3f} s   test MAE {np.mean(errors):.3f} m")
    print(f"  peopletrack, one thread                   {seq:8.3f} s   test MAE {np.mean(proto['ours_test_mae_per_split']):.3f} m   {sk / seq:6.1f}x")
    print(f"  peopletrack, rayon over splits            {par:8.3f} s                       {sk / par:6.1f}x")


if __name__ == "__main__":
    main()
