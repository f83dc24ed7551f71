"""One installed namespace: ``cpgbiped`` and nothing else (issue 23)."""
from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_a_wheel_installs_one_top_level_name_with_its_data(tmp_path):
    """What ``pip install .`` installs: the wheel's top-level names, and the data files the code
    reads (gains, feedback choice, the MJCF body)."""
    import shutil

    # from a copy of the source tree: a build/ folder left by an earlier build would put its
    # stale files into the wheel
    src = tmp_path / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(
        ".git", "out", "build", "*.egg-info", "__pycache__", ".pytest_cache", "docs"))
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps",
                        "-q", "-w", str(tmp_path)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    wheel = next(tmp_path.glob("cpgbiped-*.whl"))
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names if ".dist-info/" not in n}
    assert top == {"cpgbiped"}
    for f in ("cpgbiped/envs/control/gains.json", "cpgbiped/envs/control/gains_root.json",
              "cpgbiped/cpg/feedback_gains.json", "cpgbiped/cpg/hopf_activation.json",
              "cpgbiped/models/biped/biped.xml",
              "cpgbiped/models/biped/scene.xml", "cpgbiped/envs/cli/main.py"):
        assert f in names, f
    entry = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith("entry_points.txt")))
    assert b"cpgbiped = cpgbiped.envs.cli.main:run" in entry


def test_no_module_imports_the_folders_as_top_level_packages(tmp_path):
    """Every module of the package imported from a folder outside the repository: none of them
    reaches the old top-level names cpg, envs or models (two copies of a module would make two
    InputError classes)."""
    code = (
        "import pkgutil, sys, importlib, cpgbiped\n"
        "for pkg in ('cpgbiped.cpg', 'cpgbiped.envs', 'cpgbiped.models'):\n"
        "    m = importlib.import_module(pkg)\n"
        "    for info in pkgutil.walk_packages(m.__path__, pkg + '.'):\n"
        "        if not info.name.endswith('__main__'):\n"
        "            importlib.import_module(info.name)\n"
        "bad = sorted(k for k in sys.modules if k.split('.')[0] in ('cpg', 'envs', 'models'))\n"
        "print(len([k for k in sys.modules if k.startswith('cpgbiped.')]), bad)\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    n, bad = r.stdout.split(" ", 1)
    assert int(n) > 40 and bad.strip() == "[]"


def test_the_readme_layout_names_every_module():
    """The folder tree in the README matches the code: every subpackage of envs/ and every
    module in it appears in the Layout section."""
    text = (ROOT / "README.md").read_text()
    layout = text[text.index("## Layout"):text.index("## The one controller")]
    for sub in sorted(p for p in (ROOT / "envs").iterdir() if (p / "__init__.py").exists()):
        assert f"{sub.name}/" in layout, sub.name
        for mod in sub.glob("*.py"):
            if not mod.name.startswith("__"):
                assert mod.name in layout, f"{sub.name}/{mod.name}"
    for mod in (ROOT / "cpg").glob("*.py"):
        if not mod.name.startswith("__"):
            assert mod.name in layout or mod.stem in layout, mod.name


def test_numba_caches_live_in_a_directory_named_by_the_sources(tmp_path):
    """numba keys a cached kernel on its own file only, so a kernel inlining another module's
    function ran that function's old code after it changed (session 52). cpgbiped names the
    cache directory by a hash of every source file of the folders that hold kernels: an edit
    anywhere there (not a __pycache__ file) moves it; a process that imports the package
    compiles into it (whether numba was imported first or after); a NUMBA_CACHE_DIR the user
    set is kept, and one this package set in a parent process is recomputed. Hash directories
    that no import has used for STALE_CACHE_DAYS are removed; the one in use never is."""
    import os
    import time

    import cpgbiped

    tree = tmp_path / "cpg"
    (tree / "__pycache__").mkdir(parents=True)
    (tree / "a.py").write_text("x = 1\n")
    (tree / "b.py").write_text("y = 2\n")
    before = cpgbiped._source_hash([tree])
    (tree / "__pycache__" / "a.py").write_text("stale copy\n")
    assert cpgbiped._source_hash([tree]) == before  # compiled folders do not count
    (tree / "b.py").write_text("y = 3\n")
    assert cpgbiped._source_hash([tree]) != before
    (tree / "b.py").write_text("y = 2\n")
    assert cpgbiped._source_hash([tree]) == before

    import re

    decorator = re.compile(r"^@njit\(.*cache=True", re.M)
    kernels = [p for p in ROOT.glob("**/*.py") if decorator.search(p.read_text())
               and not {"tests", "out", "build"} & set(p.relative_to(ROOT).parts)]
    assert kernels  # every cached kernel's module lies under a hashed folder
    assert all(any(str(p).startswith(d + os.sep) for d in cpgbiped._kernel_dirs())
               for p in kernels)

    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "CPGBIPED_NUMBA_CACHE_DIR")}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), str(tmp_path)])  # this tree's package
    (tmp_path / "tiny.py").write_text("from numba import njit\n\n@njit(cache=True)\n"
                                      "def plus_one(x):\n    return x + 1\n")
    check = ("import numba, cpgbiped, glob, os; import tiny; tiny.plus_one(1); "
             "d = cpgbiped._numba_cache_dir(); print(numba.config.CACHE_DIR == d, "
             "d.startswith(os.environ['XDG_CACHE_HOME']), "
             "bool(glob.glob(os.path.join(d, '**', 'tiny.plus_one*.nbi'), recursive=True)))")
    # hash directories left by earlier sources: one unused for longer than STALE_CACHE_DAYS
    # (removed by the next import), one used lately and a folder that is not ours (kept)
    hashes = tmp_path / "cache" / "cpgbiped" / "numba"
    stale, recent, other = hashes / "0123456789abcdef", hashes / "fedcba9876543210", hashes / "x"
    for d, days in ((stale, cpgbiped.STALE_CACHE_DAYS + 1), (recent, 1),
                    (other, cpgbiped.STALE_CACHE_DAYS + 1)):
        (d / "k").mkdir(parents=True)
        (d / "k" / "kernel.nbi").write_text("")
        old = time.time() - days * 86400
        os.utime(d, (old, old))
    # an old directory reached through a link with a hash-like name: neither followed nor removed
    target = tmp_path / "elsewhere"
    (target / "k").mkdir(parents=True)
    link = hashes / "aaaaaaaaaaaaaaaa"
    link.symlink_to(target, target_is_directory=True)
    os.utime(target, (time.time() - 90 * 86400,) * 2)
    for imports in ("import numba, cpgbiped", "import cpgbiped, numba"):  # numba first, or after
        out = subprocess.run([sys.executable, "-c", f"{imports}; {check}"], capture_output=True,
                             text=True, env=env, cwd=tmp_path, check=True)
        assert out.stdout.split() == ["True", "True", "True"], out.stderr
    assert not stale.exists() and recent.is_dir() and other.is_dir()
    assert link.is_symlink() and (target / "k").is_dir()
    assert not list(hashes.glob("*.stale-*"))  # the renamed stale directory is gone too
    # the directory in use is marked at each import, so an old one in use is never removed
    ours = next(d for d in hashes.iterdir() if d not in (recent, other, link))
    os.utime(ours, (time.time() - 90 * 86400,) * 2)
    subprocess.run([sys.executable, "-c", "import cpgbiped"], env=env, cwd=tmp_path, check=True)
    assert ours.is_dir() and time.time() - ours.stat().st_mtime < 3600
    code = "import cpgbiped, numba; print(numba.config.CACHE_DIR)"
    mine = dict(env, NUMBA_CACHE_DIR=str(tmp_path / "mine"))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=mine,
                         cwd=tmp_path, check=True)
    assert out.stdout.strip() == str(tmp_path / "mine")
    inherited = dict(env, NUMBA_CACHE_DIR=str(tmp_path / "old"),
                     CPGBIPED_NUMBA_CACHE_DIR=str(tmp_path / "old"))
    out = subprocess.run([sys.executable, "-c", f"import cpgbiped, numba; {check}"],
                         capture_output=True, text=True, env=inherited, cwd=tmp_path,
                         check=True)
    assert out.stdout.split() == ["True", "True", "True"], out.stderr
