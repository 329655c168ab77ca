#!/usr/bin/env python3
"""Convert free-running zig-zag records of the Esso Osaka model (FRT-DS-ESSO) to yawcast CSVs.

Source: https://github.com/NAOE-5thLab/FRT-DS-ESSO (commit e694dfd62932bff755f3bc975b5863d649023bc0),
files data/zigzag/zigzag_*.csv, licence CC BY-NC-SA 4.0 (see tests/data/real/esso_osaka/PROVENANCE.md).

Usage (Python 3 standard library only):

    python3 bench/real/esso_osaka.py SOURCE_DIR [OUT_DIR]

SOURCE_DIR holds the source's zigzag CSVs (a clone's data/zigzag/); OUT_DIR defaults to
tests/data/real/esso_osaka/. The script rewrites exactly the committed CSVs; run it and `git diff`
to check them.

What it does to each record, in this order:
1. reads the source columns by their header names, SI units, 10 Hz (t = 0.0, 0.1, ...);
2. drops trailing rows with empty cells (one record ends in 327 empty rows);
3. checks the propeller revolutions and the zig-zag rudder amplitude against the source's table,
   and crops to the zig-zag: from 5 s before the first one-sample rudder step of at least half
   the amplitude (the zig-zag's execution) while the propeller runs at its documented
   revolutions, to the last sample at those revolutions (the source starts each run from rest,
   steered by hand, and ends it with the propeller stopped); time restarts at 0;
4. decimates 10 Hz -> 2.5 Hz by keeping every fourth row (no averaging: the source's channels are
   already filtered estimates, and the rudder holds its value between switches);
5. converts: rudder angle rad -> deg, yaw rate rad/s -> deg/s, heading rad -> deg, relative wind
   direction rad -> deg (wrapped to [-180, 180)), speed = hypot(u, v_m) in m/s (the pond has no
   current, so speed through the water is speed over ground), course over ground = heading +
   atan2(v_m, u) in deg (wrapped to [0, 360), the heading's frame);
6. writes `t_s,delta_deg,r_degps,psi_deg,u_mps,wind_speed_mps,wind_angle_deg,cog_deg` with fixed
   decimals;
7. prints, per record, the mean of the source's own true wind (`wind_velo_true`,
   `wind_dir_true`: the direction it comes from) over the rows kept, as a vector: speed and
   direction, the figures PROVENANCE.md documents and host/tests/real.rs checks diagnose's
   anemometer channel against.
"""

import csv
import math
import os
import sys

# (source file, output name, documented propeller revolutions [rps], documented rudder amplitude [deg])
RECORDS = [
    ("zigzag_31-Jul-2020_13_29_19.csv", "zz15_n12.csv", 12.0, 15.0),
    ("zigzag_31-Jul-2020_14_03_39.csv", "zz20_n12_a.csv", 12.0, 20.0),
    ("zigzag_31-Jul-2020_14_10_05.csv", "zz20_n12_b.csv", 12.0, 20.0),
    ("zigzag_31-Jul-2020_13_50_28.csv", "zz30_n12.csv", 12.0, 30.0),
]

DECIMATE = 4  # 10 Hz -> 2.5 Hz (Ts = 0.4 s)
LEAD_S = 5.0  # kept before the first zig-zag switch
SOURCE_TS = 0.1

HEADER = "t_s,delta_deg,r_degps,psi_deg,u_mps,wind_speed_mps,wind_angle_deg,cog_deg"


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    col = {name: i for i, name in enumerate(head)}
    need = [
        "t [s]",
        "u_velo [m/s]",
        "vm_velo [m/s]",
        "psi_hat [rad]",
        "r_angvelo [rad/s]",
        "n_prop [rps]",
        "delta_rudder [rad]",
        "wind_velo_relative_mid [m/s]",
        "wind_dir_relative_mid [rad]",
        "wind_velo_true [m/s]",
        "wind_dir_true [rad]",
    ]
    out = []
    for r in rows[1:]:
        cells = [r[col[n]] for n in need]
        if any(c == "" for c in cells):
            continue
        out.append(dict(zip(need, map(float, cells))))
    return out


def crop(data, n_doc, amp_doc):
    n_max = max(d["n_prop [rps]"] for d in data)
    if abs(n_max - n_doc) > 0.05:
        raise SystemExit(f"propeller {n_max} rps, the source documents {n_doc}")
    running = [i for i, d in enumerate(data) if abs(d["n_prop [rps]"] - n_max) < 1e-9]
    first_run, last_run = running[0], running[-1]
    step = 0.5 * amp_doc * math.pi / 180.0
    rud = [d["delta_rudder [rad]"] for d in data]
    # the zig-zag starts with the first one-sample rudder step of half the amplitude or more
    first_switch = next(
        i for i in range(first_run + 1, last_run + 1) if abs(rud[i] - rud[i - 1]) >= step
    )
    held = sorted(abs(x) for x in rud[first_switch : last_run + 1] if abs(x) >= step)
    amp = math.degrees(held[len(held) // 2])
    if abs(amp - amp_doc) > 1.0:
        raise SystemExit(f"rudder amplitude {amp:.2f} deg, the source documents {amp_doc}")
    start = max(first_run, first_switch - int(round(LEAD_S / SOURCE_TS)))
    return data[start : last_run + 1]


def wrap180(a):
    return (a + 180.0) % 360.0 - 180.0


def convert(src, dst, n_doc, amp_doc):
    data = crop(read(src), n_doc, amp_doc)
    t0 = data[0]["t [s]"]
    lines = [HEADER]
    kept = data[::DECIMATE]
    for k, d in enumerate(kept):
        t = round(d["t [s]"] - t0, 1)
        if abs(t - k * DECIMATE * SOURCE_TS) > 1e-6:
            raise SystemExit(f"{src}: time stamps are not uniform at row {k}")
        lines.append(
            "{:.1f},{:.3f},{:.4f},{:.3f},{:.4f},{:.3f},{:.2f},{:.2f}".format(
                t,
                math.degrees(d["delta_rudder [rad]"]),
                math.degrees(d["r_angvelo [rad/s]"]),
                math.degrees(d["psi_hat [rad]"]),
                math.hypot(d["u_velo [m/s]"], d["vm_velo [m/s]"]),
                d["wind_velo_relative_mid [m/s]"],
                wrap180(math.degrees(d["wind_dir_relative_mid [rad]"])),
                (
                    math.degrees(d["psi_hat [rad]"] + math.atan2(d["vm_velo [m/s]"], d["u_velo [m/s]"]))
                    % 360.0
                ),
            )
        )
    with open(dst, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    # the source's true wind, averaged as a vector (x0, y0: the direction it blows towards)
    wx = sum(-d["wind_velo_true [m/s]"] * math.cos(d["wind_dir_true [rad]"]) for d in kept) / len(kept)
    wy = sum(-d["wind_velo_true [m/s]"] * math.sin(d["wind_dir_true [rad]"]) for d in kept) / len(kept)
    return len(lines) - 1, (wx, wy)


def main():
    if len(sys.argv) not in (2, 3):
        raise SystemExit(__doc__)
    src_dir = sys.argv[1]
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = (
        sys.argv[2]
        if len(sys.argv) == 3
        else os.path.join(here, "..", "..", "tests", "data", "real", "esso_osaka")
    )
    os.makedirs(out_dir, exist_ok=True)
    total = [0.0, 0.0, 0]
    for src, dst, n_doc, amp_doc in RECORDS:
        n, (wx, wy) = convert(os.path.join(src_dir, src), os.path.join(out_dir, dst), n_doc, amp_doc)
        total[0] += wx * n
        total[1] += wy * n
        total[2] += n
        print(
            f"{src} -> {dst}: {n} rows; the source's true wind {math.hypot(wx, wy):.3f} m/s "
            f"from {math.degrees(math.atan2(-wy, -wx)) % 360.0:.1f} deg (mean vector)"
        )
    wx, wy = total[0] / total[2], total[1] / total[2]
    print(
        f"all records: the source's true wind {math.hypot(wx, wy):.3f} m/s "
        f"from {math.degrees(math.atan2(-wy, -wx)) % 360.0:.1f} deg (mean vector, rows weighted alike)"
    )


if __name__ == "__main__":
    main()
