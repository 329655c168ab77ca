"""The error won back by two models on a `run.sh --won-back` run's cases (bench/worlds).

won_back_table.py TSV LABEL [EXTRA]: TSV holds one line per case — world, effect, strength,
seed, oracle, best linear, the model as run, the other model, then EXTRA's column when named —
all fit % at 10 steps. Prints the cases whose linear model is ≥ 3 pp below the oracle, with
won back = (model − linear) / (oracle − linear) of both, and the median per world and
strength of both with the cases at ≥ 60 %.
"""
import collections, statistics, sys

tsv, label = sys.argv[1], sys.argv[2]
extra = sys.argv[3] if len(sys.argv) > 3 else None
rows = [l.rstrip("\n").split("\t") for l in open(tsv) if l.strip()]
print(f"| world | effect | strength | seed | oracle | linear | augmented | {label} | "
      + (f"{extra} | " if extra else "") + f"won back | {label} |")
print("|---|" * 1 + "---|" * (9 + (1 if extra else 0)))
by = collections.defaultdict(list)
for r in rows:
    w, e, st, s = r[:4]
    o, lin, a, t = map(float, r[4:8])
    if o - lin < 3.0:
        continue
    wa, wt = (a - lin) / (o - lin), (t - lin) / (o - lin)
    by[(w, st)].append((wa, wt))
    print(f"| {w} | {e} | {st} | {s} | {o:.2f} | {lin:.2f} | {a:.2f} | {t:.2f} | "
          + (f"{r[8]} | " if extra else "") + f"{100 * wa:.1f} % | {100 * wt:.1f} % |")
print(f"\n| world | strength | cases with a loss ≥ 3 pp | median won back | {label} | "
      f"≥ 60 % | ≥ 60 % ({label}) |")
print("|---|---|---|---|---|---|---|")
for (w, st), v in sorted(by.items()):
    print(f"| {w} | {st} | {len(v)} | {100 * statistics.median(x for x, _ in v):.1f} % | "
          f"{100 * statistics.median(y for _, y in v):.1f} % | "
          f"{sum(x >= 0.6 for x, _ in v)} | {sum(y >= 0.6 for _, y in v)} |")
