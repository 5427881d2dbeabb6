"""Evaluate functions of the exported C header and numpy module at points (test helper).

:func:`c_eval` compiles a small driver around ``wetcontact_closures.h`` with the system
``cc`` (skipping without one) and reads its results back at full precision (``%a``);
:func:`python_eval` imports the written module by path (it imports numpy only).
"""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

DRIVER = """\
#include <stdio.h>
#include <stdlib.h>
#include "wetcontact_closures.h"

int main(void)
{{
    double a[{n}];
    int i;
    for (;;) {{
        for (i = 0; i < {n}; ++i)
            if (scanf("%la", &a[i]) != 1)
                return 0;
        printf("%a\\n", {call});
    }}
}}
"""


def c_eval(header_dir: Path, function: str, rows: np.ndarray) -> np.ndarray:
    """``function(*row)`` of the header in ``header_dir`` for each row of ``rows`` (one
    compile per call; ``cc -std=c99 -Wall -Wextra -pedantic -Werror -O2``)."""
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc) on this machine")
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    n = rows.shape[1]
    src = header_dir / f"drive_{function}.c"
    exe = header_dir / f"drive_{function}"
    call = f"{function}({', '.join(f'a[{i}]' for i in range(n))})"
    src.write_text(DRIVER.format(n=n, call=call))
    run = subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                          "-I", str(header_dir), str(src), "-o", str(exe), "-lm"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    text = "\n".join(" ".join(float(v).hex() for v in r) for r in rows) + "\n"
    run = subprocess.run([str(exe)], input=text, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    return np.array([float.fromhex(w) if "nan" not in w else np.nan
                     for w in run.stdout.split()])


def python_module(path: Path) -> ModuleType:
    """The written module at ``path``, imported under a name of its own."""
    spec = importlib.util.spec_from_file_location(f"exported_{abs(hash(path))}", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def python_eval(module: ModuleType, function: str, rows: np.ndarray) -> np.ndarray:
    """``function`` of the imported module, vectorised over the columns of ``rows``."""
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    return np.asarray(getattr(module, function)(*rows.T), dtype=float)


MANY = """\
#include <stdio.h>
#include <stdlib.h>
#include "wetcontact_closures.h"

int main(void)
{{
    double a[8];
    int f, i, n;
    for (;;) {{
        if (scanf("%d %d", &f, &n) != 2)
            return 0;
        for (i = 0; i < n; ++i)
            if (scanf("%la", &a[i]) != 1)
                return 1;
        switch (f) {{
{cases}
        default:
            return 2;
        }}
    }}
}}
"""


def c_eval_many(header_dir: Path, calls: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``function(*row)`` for each function and row of ``calls`` (function -> rows of its
    arguments, at most 8), from one compiled driver (one compile for all functions)."""
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc) on this machine")
    names = list(calls)
    cases = []
    for f, name in enumerate(names):
        n = np.atleast_2d(calls[name]).shape[1]
        args = ", ".join(f"a[{i}]" for i in range(n))
        cases.append(f"        case {f}:\n            printf(\"%a\\n\", {name}({args}));\n"
                     "            break;")
    src, exe = header_dir / "drive_many.c", header_dir / "drive_many"
    src.write_text(MANY.format(cases="\n".join(cases)))
    run = subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                          "-I", str(header_dir), str(src), "-o", str(exe), "-lm"],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    lines, counts = [], []
    for f, name in enumerate(names):
        rows = np.atleast_2d(np.asarray(calls[name], dtype=float))
        counts.append(len(rows))
        lines += [f"{f} {rows.shape[1]} " + " ".join(float(v).hex() for v in r) for r in rows]
    run = subprocess.run([str(exe)], input="\n".join(lines) + "\n", capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    values = np.array([float.fromhex(w) if "nan" not in w else np.nan
                       for w in run.stdout.split()])
    out, start = {}, 0
    for name, n in zip(names, counts, strict=True):
        out[name] = values[start:start + n]
        start += n
    return out


def run_c_snippet(folder: Path, source: str, rows: list[str]) -> np.ndarray:
    """Compile ``source`` (a C99 program reading whitespace-separated rows on stdin and
    printing one number a line) with ``cc -O2 -Wall -Werror`` in ``folder``, feed it
    ``rows`` and return the printed numbers (skips without a compiler)."""
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc) on this machine")
    (folder / "t.c").write_text(source)
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Werror", "-o", str(folder / "t"),
                    str(folder / "t.c"), "-lm"], check=True)
    out = subprocess.run([str(folder / "t")], input="\n".join(rows) + "\n",
                         capture_output=True, text=True, check=True).stdout.split()
    return np.array([float(x) for x in out])
