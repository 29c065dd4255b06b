"""Constitutive benchmarks: one KES-FB cycle for one material point; the friction state update.

Targets: one KES cycle at 1 ms (~20,000 samples) in <= 20 ms via ``run_kes``;
``FrictionState`` trial + commit at >= 5e6 point-updates/s for N = 1e5 points.
Prints the median of repeated runs.

    python benchmarks/bench_constitutive.py [--repeats 20]
"""
import argparse
import statistics
import time

import numpy as np

from constitutive.friction import FrictionState
from constitutive.sheet import FRICTION_FRAMES, SheetLaw
from constitutive.kes import kes_profile, run_kes, kes_values
from constitutive.law import BendingState
from constitutive.material import load_material


def median_time(fn, repeats):
    fn()                                   # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=20, help="timed repetitions per case (median reported)")
    ap.add_argument("--points", type=int, default=100_000, help="material points for the state update")
    args = ap.parse_args(argv)

    law = load_material("fabric1").warp
    rows = []

    prof = kes_profile(dt=1e-3)
    t = median_time(lambda: run_kes(law, prof), args.repeats)
    rows.append(("run_kes, one KES cycle (fabric1 warp)", f"{prof.t.size} samples", f"{t * 1e3:.2f} ms", "<= 20 ms"))

    t = median_time(lambda: kes_values(*(lambda L: (L.kappa, L.moment))(run_kes(law, prof))), args.repeats)
    rows.append(("run_kes + kes_values", f"{prof.t.size} samples", f"{t * 1e3:.2f} ms", ""))

    def stepped():
        st = BendingState(law, ())
        for k in prof.kappa[:2000]:
            st.trial(k)
            st.commit(k)
    t = median_time(stepped, max(3, args.repeats // 5))
    rows.append(("BendingState stepped (Python loop, reference)", "2000 samples", f"{t * 1e3:.2f} ms",
                 f"~{t * 1e3 * prof.t.size / 2000:.0f} ms per cycle"))

    n = args.points
    rng = np.random.default_rng(0)
    st = FrictionState(law.friction, (n,))
    st.commit(rng.normal(0.0, 100.0, n))
    k = st.kappa + rng.normal(0.0, 5.0, n)

    def update():
        st.trial(k)
        st.commit(k)
    t = median_time(update, args.repeats)
    rows.append(("FrictionState trial + commit", f"N = {n:.0e}", f"{n / t / 1e6:.1f} M point-updates/s",
                 ">= 5 M/s"))

    bst = law.new_state((n,))
    def law_update():
        bst.trial(k)
        bst.commit(k)
    t = median_time(law_update, args.repeats)
    rows.append(("BendingState trial + commit (k3 + friction)", f"N = {n:.0e}",
                 f"{n / t / 1e6:.1f} M point-updates/s", ""))

    # the sheet's laws: three curvature components per point, the friction on the tensor
    sheet = SheetLaw(law, law, twist=float(law.k1))
    kv = np.stack([k, -0.5 * k, 0.3 * k], axis=-1)
    for frame in FRICTION_FRAMES:
        sst = SheetLaw(sheet.warp, sheet.weft, sheet.twist, frame).new_state((n,))
        sst.commit(np.stack([st.kappa, -0.5 * st.kappa, 0.3 * st.kappa], axis=-1))

        def sheet_update():
            sst.trial(kv)
            sst.commit(kv)
        t = median_time(sheet_update, args.repeats)
        rows.append((f"SheetState trial + commit ({frame} friction)", f"N = {n:.0e}",
                     f"{n / t / 1e6:.1f} M point-updates/s", ""))

    w = [max(len(r[i]) for r in rows) for i in range(4)]
    head = ("case", "size", "median", "target")
    w = [max(a, len(b)) for a, b in zip(w, head)]
    print("  ".join(h.ljust(x) for h, x in zip(head, w)))
    print("  ".join("-" * x for x in w))
    for r in rows:
        print("  ".join(c.ljust(x) for c, x in zip(r, w)))


if __name__ == "__main__":
    main()
