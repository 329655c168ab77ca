"""The command scaled by a stand-in for the speed from the turn (bench/speed-gain).

turn.py TAU LAG SUFFIX FIT… -- FILE…: each FILE's command `delta_deg` times (Û(t − LAG)/Ū)²,
written beside it with SUFFIX before `.csv`; Û = b₀ + b₁·s, s the yaw rate squared through a
first-order lag of TAU seconds (started at the first sample's), b₀ and b₁ fitted by least
squares to the logged speed `u_mps` of the FIT records and Ū their mean speed.
"""
import csv, math, os, sys
tau, lag, suf = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
k = sys.argv.index("--")
fit, files = sys.argv[4:k], sys.argv[k + 1:]
def read(f):
    rows = list(csv.reader(open(f)))
    h = rows[0]
    ir, iu, it = h.index("r_degps"), h.index("u_mps"), h.index("t_s")
    a = math.exp(-(float(rows[2][it]) - float(rows[1][it])) / tau)
    s, lp = None, []
    for r in rows[1:]:
        q = float(r[ir]) ** 2
        s = q if s is None else a * s + (1 - a) * q
        lp.append(s)
    return rows, lp, [float(r[iu]) for r in rows[1:]]
fr = [read(f) for f in fit]
xs = [x for _, lp, _ in fr for x in lp]
ys = [y for _, _, us in fr for y in us]
mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
b1 = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
b0 = my - b1 * mx
for f in files:
    rows, lp, _ = read(f)
    idl = rows[0].index("delta_deg")
    out = [rows[0]]
    for t, r in enumerate(rows[1:]):
        r = list(r)
        r[idl] = repr(float(r[idl]) * ((b0 + b1 * lp[max(t - lag, 0)]) / my) ** 2)
        out.append(r)
    dst = f[:-4] + suf + ".csv"
    csv.writer(open(dst + ".tmp", "w", newline="")).writerows(out)
    os.replace(dst + ".tmp", dst)
