#!/usr/bin/env python3
"""A year of a shop for measuring the suggestions page (issue 42): 30 CAM programs made from
the demo's three originals (renumbered O3001-O3030, each workingstep with a plunge and a
cutting feed, so the page must tell the feeds apart by reading the program's moves), and
EDITS dated edits on four machines over 2026: M1's operators turn the cutting feed down by
about 28 %, the others nudge it both ways. Seeded, so the same year each run.

    python3 generate.py DIR [EDITS]    # then, in DIR: ncplan import hist/cam --cam, and
                                       # ncplan import hist/mK --machine MK for K in 1..4
"""
import datetime
import os
import random
import sys

here = os.path.dirname(os.path.abspath(__file__))
demo = os.path.join(here, "..", "..", "..", "demo", "history", "cam", "2026-01-05")
out = sys.argv[1]
edits = int(sys.argv[2]) if len(sys.argv) > 2 else 400
rng = random.Random(42)
originals = [open(os.path.join(demo, f"O210{i}.nc"), encoding="utf-8").read() for i in (1, 2, 3)]


def write(rel, text):
    path = os.path.join(out, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


programs = {}
for n in range(30):
    text = originals[n % 3]
    for i in (1, 2, 3):
        text = text.replace(f"O210{i}", f"O{3001 + n}")
    programs[3001 + n] = text
    write(f"hist/cam/2025-12-01/O{3001 + n}.nc", text)
for m in range(1, 5):
    os.makedirs(os.path.join(out, f"m{m}"), exist_ok=True)
os.makedirs(os.path.join(out, "cam"), exist_ok=True)
os.makedirs(os.path.join(out, "var"), exist_ok=True)
day0 = datetime.date(2026, 1, 1)
for k in range(edits):
    machine = 1 + k % 4
    day = day0 + datetime.timedelta(days=rng.randrange(365))
    n = 3001 + rng.randrange(30)
    f = round(1200 * (0.72 + rng.uniform(-0.02, 0.02))) if machine == 1 else round(1200 * (1 + rng.uniform(-0.03, 0.03)))
    write(f"hist/m{machine}/{day.isoformat()}_{k}/O{n}.nc", programs[n].replace("F1200.", f"F{f}."))
machines = "".join(f"[[machine]]\nname = 'M{m}'\npath = 'm{m}'\ndialect = 'fanuc'\n" for m in range(1, 5))
write("ncplan.toml", f"site = 'YEAR'\n[database]\npath = 'var/ncplan.db'\n[[cam]]\npath = 'cam'\ndialect = 'fanuc'\n{machines}"
      "[suggest]\nunreviewed = true\n")
