"""The examples in the documentation run: the Python blocks of docs/python.md
and README.md, and examples/python_demo.py (make demo)."""
import os
import re
import subprocess
import sys

import pm
from conftest import TOP


def test_docs_python_md_example_runs(tmp_path, monkeypatch, capsys):
    text = open(os.path.join(TOP, "docs", "python.md")).read()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "no python block in docs/python.md"
    monkeypatch.chdir(TOP)
    for code in blocks:
        code = code.replace("/tmp/mount.pm", str(tmp_path / "mount.pm"))
        exec(compile(code, "docs/python.md", "exec"), {})
    out = capsys.readouterr().out
    assert "N = 300, P = 22, sigma = 2.203 arcsec" in out
    assert "['refraction', 'ha_periodic']" in out
    assert "tests/data/bad_pier.dat:2: field 5 (pier)" in out


def test_readme_python_block_runs(monkeypatch):
    """README.md's Python snippet runs as written (every name it uses defined
    there), from the repository root."""
    text = open(os.path.join(TOP, "README.md")).read()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "no python block in README.md"
    monkeypatch.chdir(TOP)
    for code in blocks:
        g = {}
        exec(compile(code, "README.md", "exec"), g)
        assert g["enc_ha"].shape == g["app_ha"].shape


def test_python_demo_runs():
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(pm.__file__)))
    p = subprocess.run([sys.executable, "examples/python_demo.py"], cwd=TOP, env=env,
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "found ha_periodic" in p.stdout and "FormatError: tests/data/bad_pier.dat:2:" in p.stdout
