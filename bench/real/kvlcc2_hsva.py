#!/usr/bin/env python3
"""Convert HSVA's free-running zig-zag records of the KVLCC2 model (SIMMAN 2008) to yawcast CSVs.

Source: the 13 files `HSVA_CPMC_KVLCC2_Z_*.dat` (HSVA's free-running tests of the 7 m KVLCC2
model, scale 1:45.7, for the SIMMAN 2008 workshop) as shipped in
https://github.com/martinlarsalbert/System-identification-of-Vessel-Manoeuvring-Models
(data/01_raw/kvlcc2_hsva/raw_data/; column names from its conf/base/catalog/load_hsva.yml).
Neither the repository nor the files state a licence for the data, so yawcast does not
redistribute them: `bench/real/hsva.sh` fetches them and runs this script at bench time.

Usage (Python 3 standard library only):

    python3 bench/real/kvlcc2_hsva.py SOURCE_DIR OUT_DIR [--every N] [--command] [--froude S]
                                      [--rate-digits D]

What it does to each record, in this order:
1. reads the 12 columns (time s, x0 m, y0 m, heading deg, the ground velocity's x and y in
   the earth frame m/s (the catalog's `u` and `v`: they are the positions' derivative, not
   the ship-frame velocities), yaw rate deg/s, roll rate, rudder angle deg, propeller rps,
   thrust N, torque Nm; 20 Hz) after the 4 title lines;
   the title's third line names the zig-zag (`Z20/5`: rudder 20°, heading 5°);
2. checks that the yaw rate is the heading's derivative (slope 1 within 2 %), that the ground
   velocity is the positions' derivative (within 3 %) and that the rudder reaches the
   amplitude the file name gives (within 0.2°);
3. keeps every N-th row (default 3: 20 Hz -> 6.67 Hz, Ts 0.15 s, the sample time of
   `simulate --world kvlcc2 --scale 7`);
4. converts to yawcast's signs: the source's rudder is negative to turn to starboard (its yaw
   rate is positive to starboard, as yawcast's), so `delta_deg` = −rudder; speed over ground =
   hypot(u, v) (a towing tank has no current); course over ground = atan2(v, u);
   with `--command`, `delta_deg` is instead the zig-zag's command: ±amplitude from the sample
   where the measured rudder starts moving towards it (0 before the first), so the steering
   gear's rate is left to the records;
5. with `--froude S` (the scale, 45.7), Froude-scales the record to the ship: times × √S,
   yaw rate ÷ √S, speed × √S (angles as they are), to set beside records given at full
   scale (MARIN's: `--every 2 --froude 45.7` gives their Ts, 0.676 s); with `--rate-digits
   D`, writes the yaw rate to D significant figures, as MARIN's records give it (3);
6. writes `t_s,delta_deg,r_degps,psi_deg,u_mps,cog_deg` to OUT_DIR/<name>.csv, name
   `z<rudder>_<heading>[_p|_s]` (e.g. `z20_05`, `z10_10_p`), and prints per record its rows,
   length, mean speed and the rudder's largest rate (deg/s, over one source sample).
"""

import math
import os
import re
import sys


def read(path):
    with open(path, encoding="cp1252") as f:
        lines = f.read().splitlines()
    title = lines[2].strip()
    rows = []
    for i, line in enumerate(lines[4:], start=5):
        if not line.strip():
            continue
        cells = line.split()
        if len(cells) != 12:
            sys.exit(f"{path}: line {i}: {len(cells)} fields, expected 12")
        rows.append([float(c) for c in cells])
    return title, rows


def command(rudder, amp):
    """The zig-zag's command: ±amp from the sample where the rudder starts towards it."""
    out = []
    cmd = 0.0
    for i, d in enumerate(rudder):
        if i > 0:
            step = d - rudder[i - 1]
            if step > 0.05 and cmd <= 0.0 and d > -amp + 0.5:
                cmd = amp
            elif step < -0.05 and cmd >= 0.0 and d < amp - 0.5:
                cmd = -amp
        out.append(cmd)
    return out


def main():
    args = sys.argv[1:]
    every = 3
    use_command = "--command" in args
    args = [a for a in args if a != "--command"]
    if "--every" in args:
        i = args.index("--every")
        every = int(args[i + 1])
        del args[i : i + 2]
    digits = None
    if "--rate-digits" in args:
        i = args.index("--rate-digits")
        digits = int(args[i + 1])
        del args[i : i + 2]
    froude = 1.0
    if "--froude" in args:
        i = args.index("--froude")
        froude = math.sqrt(float(args[i + 1]))
        del args[i : i + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    src, out = args
    os.makedirs(out, exist_ok=True)
    names = sorted(n for n in os.listdir(src) if n.startswith("HSVA_CPMC_KVLCC2_Z_"))
    if len(names) != 13:
        sys.exit(f"{src}: {len(names)} HSVA_CPMC_KVLCC2_Z_*.dat files, expected 13")
    for name in names:
        m = re.match(r"HSVA_CPMC_KVLCC2_Z_(\d+)_(\d+)(?:_([PS]))?\.dat$", name)
        if not m:
            sys.exit(f"{name}: not a zig-zag file name")
        amp = float(m.group(1))
        title, rows = read(os.path.join(src, name))
        ts = rows[1][0] - rows[0][0]
        # the yaw rate is the heading's derivative
        num = den = 0.0
        for a, b in zip(rows[:-2], rows[2:]):
            rate = (b[3] - a[3]) / (b[0] - a[0])
            mid = (a[6] + b[6]) / 2.0
            num += rate * mid
            den += mid * mid
        if abs(num / den - 1.0) > 0.02:
            sys.exit(f"{name}: heading's derivative / yaw rate = {num / den:.3f}, expected 1")
        num = den = 0.0
        for a, b in zip(rows[:-20], rows[20:]):
            gx, gy = (a[4] + b[4]) / 2.0, (a[5] + b[5]) / 2.0
            dt = b[0] - a[0]
            num += (b[1] - a[1]) / dt * gx + (b[2] - a[2]) / dt * gy
            den += gx * gx + gy * gy
        if abs(num / den - 1.0) > 0.03:
            sys.exit(f"{name}: positions' derivative / ground velocity = {num / den:.3f}, expected 1")
        peak = max(abs(r[8]) for r in rows)
        if abs(peak - amp) > 0.2:
            sys.exit(f"{name} ({title}): rudder reaches {peak:.2f}°, expected {amp}°")
        rudder = [-r[8] for r in rows]
        cmd = command(rudder, amp) if use_command else rudder
        slew = max(abs(b - a) for a, b in zip(rudder, rudder[1:])) / (ts * froude)
        base = "z{}_{}".format(m.group(1), m.group(2)) + (
            "_" + m.group(3).lower() if m.group(3) else ""
        )
        path = os.path.join(out, base + ".csv")
        kept = rows[::every]
        cmd = cmd[::every]
        t0 = kept[0][0]
        def rate(x):
            return f"{x:.6f}" if digits is None else f"{x:.{digits - 1}e}"

        with open(path + ".tmp", "w") as f:
            f.write("t_s,delta_deg,r_degps,psi_deg,u_mps,cog_deg\n")
            for r, d in zip(kept, cmd):
                u, v = r[4], r[5]
                cog = math.degrees(math.atan2(v, u)) % 360.0
                f.write(
                    f"{(r[0] - t0) * froude:.4f},{d:.4f},{rate(r[6] / froude)},{r[3]:.4f},"
                    f"{math.hypot(u, v) * froude:.5f},{cog:.4f}\n"
                )
        os.replace(path + ".tmp", path)
        speed = froude * sum(math.hypot(r[4], r[5]) for r in kept) / len(kept)
        print(
            f"{base}: {title}, {len(kept)} rows, {(kept[-1][0] - t0) * froude:.1f} s, "
            f"speed {speed:.3f} m/s, rudder rate up to {slew:.1f} deg/s"
        )


if __name__ == "__main__":
    main()
