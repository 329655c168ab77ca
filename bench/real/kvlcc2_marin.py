#!/usr/bin/env python3
"""Convert MARIN's free-running records of the KVLCC2 (SIMMAN 2008) to yawcast CSVs.

Source: the 6 files `MARIN_FREE_KVLCC2_{zz_10,zz_-10,zz_20,zz_-20,tc_35,tc_-35}_m.dat`
(MARIN's free-running tests of the 7 m KVLCC2 model, scale 1:45.7, for the SIMMAN 2008
workshop, given at full scale) as shipped in
https://github.com/martinlarsalbert/System-identification-of-Vessel-Manoeuvring-Models
(data/01_raw/kvlcc2/; column names from its notebooks/20.01_kvlcc2.ipynb). Neither the
repository nor the files state a licence for the data, so yawcast does not redistribute
them: `bench/real/marin.sh` runs this script on a copy at bench time.

Usage (Python 3 standard library only):

    python3 bench/real/kvlcc2_marin.py SOURCE_DIR OUT_DIR [--every N] [--command]

What it does to each record, in this order:
1. reads the 11 columns (time s, x0 m, y0 m, roll deg, heading deg, the ground velocity's
   x and y in the earth frame m/s, roll rate, yaw rate deg/s, rudder angle deg, propeller
   rpm) after the 2 title lines;
2. the time column is printed to 3 significant figures (1 s steps past 100 s, with repeated
   stamps), so the sample time is the slope of a least-squares line through the stamps
   (0.13526 s in every file: the model's 0.02 s at full scale), each stamp checked to lie
   within its rounding and a quarter step of that line; times are rewritten as the sample's
   index times that step;
3. checks that the yaw rate is the heading's derivative (slope 1 within 3 %), that the
   ground velocity is the positions' derivative, and that a zig-zag's rudder reaches the
   amplitude its title gives (within 1°: the ±10° runs overshoot to 10.7°);
4. keeps every N-th row (default 5: Ts 0.676 s, the model's 0.1 s at full scale; HSVA's
   20 Hz records at every 2nd row scaled by `kvlcc2_hsva.py --froude 45.7` sample the same);
5. converts to yawcast's signs: the source's rudder is positive to turn to port (its yaw
   rate is positive to starboard, as yawcast's), so `delta_deg` = −rudder; speed over ground
   = the ground velocity's length; course over ground its direction; with `--command`,
   `delta_deg` is instead the manoeuvre's command: from the sample where each move of the
   measured rudder starts, the angle it heads for (−amplitude, 0 or +amplitude: the
   turning circles' pull-out returns it to 0), so the steering gear's rate is left to the
   records;
6. writes `t_s,delta_deg,r_degps,psi_deg,u_mps,cog_deg` to OUT_DIR/<name>.csv, name
   `zz10`, `zz-10`, `zz20`, `zz-20`, `tc35`, `tc-35` (the first rudder's sign as the
   source's), and prints per record its rows, length, mean speed and the rudder's largest
   rate (deg/s over 5 source samples, as the records' resolution of 0.1° allows).
"""

import math
import os
import re
import sys

NAMES = ["zz_10", "zz_-10", "zz_20", "zz_-20", "tc_35", "tc_-35"]


def read(path):
    with open(path, encoding="latin-1") as f:
        lines = f.read().splitlines()
    title = lines[1].strip()
    rows = []
    for i, line in enumerate(lines[2:], start=3):
        if not line.strip():
            continue
        cells = line.split()
        if len(cells) != 11:
            sys.exit(f"{path}: line {i}: {len(cells)} fields, expected 11")
        rows.append([float(c) for c in cells])
    return title, rows


def half_ulp(x):
    """Half the last digit of x printed to 3 significant figures (as `%.2E`)."""
    if x == 0.0:
        return 0.005
    return 0.5 * 10.0 ** (math.floor(math.log10(abs(x))) - 2)


def sample_time(path, times):
    """The step of a least-squares line through the stamps; each stamp within its rounding
    and a quarter step of that line (no sample missing or repeated)."""
    n = len(times)
    mi = (n - 1) / 2.0
    mt = sum(times) / n
    step = sum((i - mi) * (t - mt) for i, t in enumerate(times)) / sum(
        (i - mi) ** 2 for i in range(n)
    )
    at = mt - step * mi
    for i, t in enumerate(times):
        if abs(t - (at + step * i)) > half_ulp(t) + 0.25 * step:
            sys.exit(f"{path}: sample {i + 1} stamped {t} s, {at + step * i:.3f} s expected")
    return step


def command(rudder, amp):
    """The manoeuvre's command: the angle each move of the rudder heads for (the nearest of
    −amp, 0 and +amp to where it comes to rest), from the sample where the move starts.

    A move is seen once the rudder has left the angle it rests at by 1° (the records' 0.1°
    resolution and the gear's own offsets are below that); its start is the last sample,
    going back, where the rudder was not yet moving that way, and its end the first where
    it moves less than 0.3° over the next 5 samples."""
    n = len(rudder)
    out = [0.0] * n
    held, i = rudder[0], 1
    while i < n:
        d = rudder[i]
        if abs(d - held) <= 1.0:
            i += 1
            continue
        sign = 1.0 if d > held else -1.0
        j = i
        while j > 0 and sign * (rudder[j] - rudder[j - 1]) > 0.05:
            j -= 1
        k = i
        while k + 5 < n and abs(rudder[k + 5] - rudder[k]) >= 0.3:
            k += 1
        held = rudder[k]
        target = min((-amp, 0.0, amp), key=lambda c: abs(c - held))
        for m in range(j, n):
            out[m] = target
        i = k + 1
    return out


def main():
    args = sys.argv[1:]
    every = 5
    use_command = "--command" in args
    args = [a for a in args if a != "--command"]
    if "--every" in args:
        i = args.index("--every")
        every = int(args[i + 1])
        del args[i : i + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    src, out = args
    os.makedirs(out, exist_ok=True)
    for key in NAMES:
        name = f"MARIN_FREE_KVLCC2_{key}_m.dat"
        path = os.path.join(src, name)
        if not os.path.exists(path):
            sys.exit(f"{path}: missing (expected the 6 MARIN_FREE_KVLCC2_*_m.dat files)")
        title, rows = read(path)
        m = re.search(r":\s*(-?\d+)", title)
        if not m:
            sys.exit(f"{name}: title '{title}' names no rudder angle")
        first = float(m.group(1))
        amp = abs(first)
        ts = sample_time(name, [r[0] for r in rows])
        # the yaw rate is the heading's derivative, the ground velocity the positions'
        lag = 10
        num = den = 0.0
        vx = vy = vv = 0.0
        for a, b in zip(rows[:-lag], rows[lag:]):
            mid = (a[8] + b[8]) / 2.0
            num += (b[4] - a[4]) / (lag * ts) * mid
            den += mid * mid
            ux, uy = (a[5] + b[5]) / 2.0, (a[6] + b[6]) / 2.0
            vx += (b[1] - a[1]) / (lag * ts) * ux + (b[2] - a[2]) / (lag * ts) * uy
            vv += ux * ux + uy * uy
        if abs(num / den - 1.0) > 0.03:
            sys.exit(f"{name}: heading's derivative / yaw rate = {num / den:.3f}, expected 1")
        if abs(vx / vv - 1.0) > 0.03:
            sys.exit(f"{name}: positions' derivative / ground velocity = {vx / vv:.3f}, expected 1")
        rudder = [-r[9] for r in rows]
        peak = max(abs(d) for d in rudder)
        if key.startswith("zz") and abs(peak - amp) > 1.0:
            sys.exit(f"{name} ({title}): rudder reaches {peak:.2f}°, expected {amp}°")
        cmd = command(rudder, amp) if use_command else rudder
        slew = max(abs(b - a) for a, b in zip(rudder, rudder[5:])) / (5 * ts)
        base = key.replace("_", "")
        out_path = os.path.join(out, base + ".csv")
        kept = rows[::every]
        cmd = cmd[::every]
        with open(out_path + ".tmp", "w") as f:
            f.write("t_s,delta_deg,r_degps,psi_deg,u_mps,cog_deg\n")
            for i, (r, d) in enumerate(zip(kept, cmd)):
                gx, gy = r[5], r[6]
                cog = math.degrees(math.atan2(gy, gx)) % 360.0
                f.write(
                    f"{i * every * ts:.4f},{d:.4f},{r[8]:.5f},{r[4]:.4f},"
                    f"{math.hypot(gx, gy):.5f},{cog:.4f}\n"
                )
        os.replace(out_path + ".tmp", out_path)
        speed = sum(math.hypot(r[5], r[6]) for r in kept) / len(kept)
        print(
            f"{base}: {title}, Ts {every * ts:.5f} s, {len(kept)} rows, "
            f"{(len(kept) - 1) * every * ts:.1f} s, speed {speed:.3f} m/s, "
            f"rudder rate up to {slew:.2f} deg/s"
        )


if __name__ == "__main__":
    main()
