"""``wetcontact export csv``: one row per (point, model, gap) from the store."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from wetcontact.cli import main
from wetcontact.store import Store
from wetcontact.study import load_study
from wetcontact.sweep import sweep

ROOT = Path(__file__).resolve().parents[1]


def study(tmp_path: Path, case: str, body: str) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(f'name = "s"\nbase = "{ROOT / "cases" / case}"\n' + body, encoding="utf-8")
    return p


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_rows_columns_values_and_statuses(tmp_path, capsys):
    s = study(tmp_path, "brenner-immersed-sphere-wall.toml", 'models = ["brenner", "meniscus"]\n'
              '[axes]\n"motion.velocity" = [1e-3, 2e-3]\n"liquid.viscosity" = [1.2]\n')
    st = Store(tmp_path / "r.h5")
    res = sweep(load_study(s).points(), st, workers=0, progress=False)
    out = tmp_path / "o.csv"
    assert main(["export", "csv", str(s), "--store", str(st.path), "--out", str(out)]) == 0
    got = rows(out)
    assert list(got[0]) == ["motion.velocity", "liquid.viscosity", "model", "gap",
                            "force_viscous", "force_capillary", "force_total", "status",
                            "reason"]
    assert len(got) == 2 * 2 * 26  # scenes x models x gaps
    pts = load_study(s).points()
    brenner = [r for r in got if r["model"] == "brenner"]
    curve = res.curve(pts[0])
    first = brenner[:26]
    assert all(r["motion.velocity"] == "0.001" and r["status"] == "ok" for r in first)
    assert [float(r["force_viscous"]) for r in first] == curve.force_viscous.tolist()
    assert [float(r["gap"]) for r in first] == curve.gap.tolist()
    assert all(r["force_capillary"] == "" for r in brenner)  # not modelled: empty, not 0
    men = [r for r in got if r["model"] == "meniscus"]
    assert all(r["status"] == "failed" and "immersed" in r["reason"] and r["force_total"] == ""
               for r in men)
    # a point never swept is 'missing'
    s2 = study(tmp_path, "brenner-immersed-sphere-wall.toml", 'models = ["brenner"]\n'
               '[axes]\n"motion.velocity" = [1e-3, 5e-3]\n')
    assert main(["export", "csv", str(s2), "--store", str(st.path), "--out", str(out)]) == 0
    assert {r["status"] for r in rows(out)} == {"ok", "missing"}
    assert "26 ok" in capsys.readouterr().out
    assert main(["export", "csv", str(s2), "--store", str(st.path), "--out", str(out),
                 "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["format"] == "csv" and info["out"] == str(out) and info["wall_time_s"] >= 0
    assert (info["rows"], info["ok"], info["missing"]) == (52, 26, 26)


def test_past_rupture_rows_are_no_bridge(tmp_path):
    s = study(tmp_path, "dem-pendular-bridge-100um.toml", 'models = ["meniscus", "willett"]\n'
              'preset = "fast"\n[set]\n"motion.gap_over_rupture" = [0.5, 1.5]\n')
    st = Store(tmp_path / "r.h5")
    sweep(load_study(s).points(), st, workers=0, progress=False)
    out = tmp_path / "o.csv"
    assert main(["export", "csv", str(s), "--store", str(st.path), "--out", str(out)]) == 0
    men = [r for r in rows(out) if r["model"] == "meniscus"]
    assert [r["status"] for r in men] == ["ok", "no-bridge"]
    assert float(men[0]["force_capillary"]) < 0 and float(men[1]["force_capillary"]) == 0
    # a closure past its own rupture distance too (it said 'ok' with a force of 0)
    wil = [r for r in rows(out) if r["model"] == "willett"]
    assert [r["status"] for r in wil] == ["ok", "no-bridge"]
    assert float(wil[1]["force_capillary"]) == 0


def test_export_bad_paths_exit_2_one_line(tmp_path, capsys):
    s = study(tmp_path, "brenner-immersed-sphere-wall.toml", 'models = ["brenner"]\n')
    assert main(["export", "csv", str(s), "--store", str(tmp_path / "none.h5"), "--out",
                 str(tmp_path / "o.csv")]) == 2
    assert main(["export", "csv", str(s), "--store", str(s), "--out",
                 str(tmp_path / "no" / "o.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 2 and "run `wetcontact sweep` first" in err and "no" in err
