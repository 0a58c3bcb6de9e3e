# Every file of dmi-sweep (python/, its tests, bench/bench_sweep.py, the main
# job's sweep stage) carries the license line.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LINE = "SPDX-License-Identifier: GPL-3.0-or-later"


def files() -> list[Path]:
    found = [p for p in (ROOT / "python").rglob("*") if p.is_file() and p.suffix in (".py", ".toml", ".md")
             and "__pycache__" not in p.parts and ".egg-info" not in str(p)]
    found += sorted((ROOT / "tests" / "sweep").iterdir())
    found += [ROOT / "bench" / "bench_sweep.py", ROOT / "scripts" / "sweep_ex43.sh"]
    return [p for p in found if p.is_file() and "__pycache__" not in p.parts]


def test_license_line_in_every_file():
    checked = files()
    assert ROOT / "python" / "README.md" in checked and len(checked) > 15
    missing = [str(p.relative_to(ROOT)) for p in checked if LINE not in p.read_text()]
    assert not missing, f"no '{LINE}' in {missing}"
