"""Shared pieces of the benchmarks: result files (written atomically), memory readings, the machine."""

from __future__ import annotations

import csv
import io
import json
import os
import platform
import resource
import sys
import time
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parent
REPO = BENCH_DIR.parent
RESULTS = BENCH_DIR / "results"
COLUMNS = ("engine", "distribution", "n", "repeat", "seconds", "peak_mib", "kind")
CHECK_COLUMNS = ("engine", "distribution", "n", "kind", "status", "detail")
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS")


def atomic_write(path: Path, text: str | bytes) -> None:
    """Write a file through a temporary sibling and a rename: never half a file."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    if isinstance(text, bytes):
        tmp.write_bytes(text)
    else:
        tmp.write_text(text)
    os.replace(tmp, path)


def write_csv(path: Path, rows: list[dict], columns=COLUMNS) -> None:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(columns), extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    atomic_write(path, buf.getvalue())


def read_csv(path: Path) -> list[dict]:
    if not Path(path).exists():
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def rss_mib() -> float:
    """Resident set size now (Linux), else the peak so far."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (OSError, ValueError, IndexError):
        return maxrss_mib()


def release_free_memory() -> None:
    """Collect garbage and hand the allocator's free pages back to the system (glibc).

    Without it a build reuses pages its predecessor in the same process freed
    and reads as using almost no memory.
    """
    import ctypes
    import gc

    gc.collect()
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):
        pass


def reset_peak() -> bool:
    """Start a new peak resident set measurement (Linux >= 4.0); False where that is not possible."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def maxrss_mib() -> float:
    """Peak resident set size of this process so far (since the last reset_peak, on Linux).

    VmHWM rather than ru_maxrss: at exec the kernel carries the parent's peak
    over into ru_maxrss, which then hides every peak smaller than the parent's.
    """
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    except (OSError, ValueError, IndexError):
        pass
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 2**20 if sys.platform == "darwin" else peak / 1024.0  # bytes on macOS, KiB on Linux


def subprocess_env() -> dict:
    """The environment of a worker: the checkout first on the import path."""
    path = os.environ.get("PYTHONPATH", "")
    return dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(REPO), path) if p))


def machine() -> dict:
    """CPU, cores, versions and thread settings, recorded with every result."""
    import numpy as np

    info = {"date": time.strftime("%Y-%m-%d %H:%M:%S %z"), "cpu": platform.processor() or platform.machine()}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    info["cores"] = os.cpu_count()
    if hasattr(os, "sched_getaffinity"):
        info["cores_usable"] = len(os.sched_getaffinity(0))
    try:
        info["memory_gib"] = round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30, 1)
    except (ValueError, OSError):
        pass
    if hasattr(os, "getloadavg"):
        info["load_average"] = [round(v, 2) for v in os.getloadavg()]
    info["platform"] = platform.platform()
    info["python"] = platform.python_version()
    versions = {"numpy": np.__version__}
    for mod in ("scipy", "shapely", "triangle", "matplotlib", "tvoronoi"):
        try:
            versions[mod] = getattr(__import__(mod), "__version__", "installed")
        except ImportError:
            versions[mod] = None
    try:
        import shapely

        versions["geos"] = shapely.geos_version_string
    except ImportError:
        pass
    info["versions"] = versions
    info["thread_env"] = {v: os.environ.get(v, "unset") for v in THREAD_VARS}
    try:
        import scipy.spatial  # noqa: F401  (loads the BLAS that scipy links, if any)
        from threadpoolctl import threadpool_info

        info["threadpools"] = [
            {k: p.get(k) for k in ("internal_api", "prefix", "version", "num_threads", "threading_layer")}
            for p in threadpool_info()
        ]
    except ImportError:
        info["threadpools"] = "threadpoolctl not installed"
    return info


def describe_machine(info: dict) -> str:
    """One paragraph for the reports."""
    v = info.get("versions", {})
    pools = info.get("threadpools")
    if isinstance(pools, list):
        pools = (
            ", ".join(
                f"{p['internal_api']} {p.get('version') or ''} {p['num_threads']} threads".replace("  ", " ")
                for p in pools
            )
            or "none loaded"
        )
    env = ", ".join(f"{k}={val}" for k, val in info.get("thread_env", {}).items())
    libs = ", ".join(f"{k} {val}" for k, val in v.items() if val)
    return (
        f"{info.get('cpu')}, {info.get('cores')} cores ({info.get('cores_usable', '?')} usable), "
        f"{info.get('memory_gib', '?')} GiB; load average at start {info.get('load_average')}; "
        f"Python {info.get('python')} on {info.get('platform')}; {libs}. "
        f"Thread pools: {pools}; {env}. Run {info.get('date')}."
    )


def send(stream, obj) -> None:
    """One JSON message per line."""
    stream.write(json.dumps(obj) + "\n")
    stream.flush()


def parse_sizes(text: str) -> list[int]:
    """'100,1k,10k,1M' -> [100, 1000, 10000, 1000000]."""
    out = []
    for part in text.split(","):
        part = part.strip().lower()
        mult = {"k": 1_000, "m": 1_000_000}.get(part[-1:], 1)
        out.append(int(float(part[:-1] if mult > 1 else part) * mult))
    return out
