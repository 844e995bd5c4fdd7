"""The one-command GPU benchmark suite runs (``--quick``, small sizes on llvmpipe), so it never rots
before it meets a real GPU: every section reports rows, the report names the thesis's and the
anchors' figures, and the JSON holds the same sections."""
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_gpu_suite_runs_quick_and_writes_markdown_and_json(tmp_path):
    run = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "gpu_suite.py"), "--quick", "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=240, cwd=ROOT, env={**os.environ, "ATMOS_HEADLESS": "1"})
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-4000:]
    report = json.loads((tmp_path / "gpu_suite.json").read_text())
    sections = report["sections"]
    assert list(sections) == ["automaton", "tasks", "shading", "clouds", "fog", "pacing", "sunset", "raymarch",
                              "additions"]
    for name, section in sections.items():
        assert "error" not in section, (name, section.get("error"))
        assert section["rows"], f"section {name} has no rows"
    configs = {r["config"] for r in sections["clouds"]["rows"]}
    assert {"none", "VFD", "VFD+ESS", "1/2 res, VFD+ESS", "1/2 res, VFD+ESS+LOD 4px"} <= configs
    assert {r["cover"] for r in sections["clouds"]["rows"]} == {"low", "medium", "high"}
    parts = [r["part"] for r in sections["sunset"]["rows"]]
    assert "pass cloud_raymarch" in parts and "whole frame (one timer query)" in parts
    assert all(r["gpu_ms"] > 0 for r in sections["sunset"]["rows"] if r["part"].startswith("pass "))
    march = {r["renderer"]: r for r in sections["raymarch"]["rows"]}
    assert set(march) == {"sprites", "march"} and march["march"]["pass"] == "cloud_raymarch"
    assert all(r["frame_ms"] > 0 and r["pass_gpu_ms"] > 0 for r in march.values()), march
    added = {(r["demo"], r["variant"], r["pass"]) for r in sections["additions"]["rows"]}
    assert ("glider", "camera motion only", "temporal_aa") in added and ("flight", "one type (cumulus)", "cloud_raymarch") in added
    assert all(r["gpu_ms"] > 0 for r in sections["additions"]["rows"])
    text = (tmp_path / "gpu_suite.md").read_text()
    for figure in ("Table 8.1", "Tables 8.2–8.4", "sec. 8.2", "Nubis", "12.5", "118", "20 fps"):
        assert figure in text, figure
    assert text.count("\n| ") > 40, "tables, not just headings"
