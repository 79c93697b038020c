"""The allocator a build's arrays come from (kernels/pages.pyx): large arrays in mappings of their own."""

import os
import sys
import threading

import numpy as np
import pytest
from numpy._core.multiarray import get_handler_name

import tvoronoi
from tests.invariants import assert_same_diagram
from tvoronoi import engines
from tvoronoi.api import default_bbox
from tvoronoi.build import assemble, build_arrays
from tvoronoi.generators import generate
from tvoronoi.kernels import pages

BIG = (1 << 20) // 8 + 1000  # doubles: just over the size that gets a mapping


def test_arrays_made_inside_come_from_the_handler_and_the_old_one_returns():
    before = get_handler_name(np.empty(3))
    with build_arrays():
        small, big = np.empty(10), np.empty(BIG)
        assert get_handler_name(small) == get_handler_name(big) == "tvoronoi_pages"
    assert get_handler_name(np.empty(BIG)) == before
    big[:] = 1.5  # still usable, and freed by its own handler after the block
    assert big.sum() == 1.5 * BIG


def test_the_handler_is_left_on_an_exception():
    before = get_handler_name(np.empty(3))
    with pytest.raises(RuntimeError):
        with build_arrays():
            raise RuntimeError("stop")
    assert get_handler_name(np.empty(3)) == before


def test_another_thread_keeps_its_own_allocator():
    names = []
    with build_arrays():
        t = threading.Thread(target=lambda: names.append(get_handler_name(np.empty(BIG))))
        t.start()
        t.join()
    assert names and names[0] != "tvoronoi_pages"


@pytest.mark.parametrize("n", [5, BIG, 4 * BIG])
def test_zeros_grow_and_shrink_keep_the_data(n):
    with build_arrays():
        z = np.zeros(n)
        assert not z.any()
        a = np.arange(n, dtype=np.float64)
        a.resize(3 * n, refcheck=False)  # a mapping grows in place or moves, with its pages
        assert np.array_equal(a[:n], np.arange(n)) and not a[n:].any()
        a.resize(n // 2 + 1, refcheck=False)
        assert np.array_equal(a, np.arange(n // 2 + 1))
        b = np.arange(7, dtype=np.float64)
        b.resize(n + 7, refcheck=False)  # from malloc to a mapping when it grows past 1 MiB
        assert np.array_equal(b[:7], np.arange(7)) and not b[7:].any()


def test_a_build_equals_one_made_with_the_default_allocator_and_no_room():
    """The build's arrays under the handler, the crossings written into the dual's room: the same Diagram as
    the arrays of numpy's own allocator and the crossings in a copy."""
    pts = generate("clustered", 30_000, seed=4)
    box = default_bbox(pts)
    e = engines.scale_exponent(pts)
    t = engines.spatial(engines.run(pts[:, 0], pts[:, 1], engine="incremental", exponent=e))
    out = t.voronoi(1)
    assert "vertex_room" not in out
    plain = assemble(pts, box, e, t.sites.perm, t.sites.xs, t.sites.ys, out, engine="incremental")
    assert get_handler_name(owner(plain.cell_points)) != "tvoronoi_pages"
    built = tvoronoi.voronoi(pts, threads=1)
    assert get_handler_name(owner(built.cell_points)) == "tvoronoi_pages"
    assert_same_diagram(plain, built)


def owner(a: np.ndarray) -> np.ndarray:
    while isinstance(a.base, np.ndarray):
        a = a.base
    return a


def resident_mib() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


@pytest.mark.skipif(not pages.MAPS or not os.path.exists("/proc/self/statm"), reason="no mappings here")
def test_a_freed_array_is_handed_back():
    """Unlike the C heap's blocks below its threshold, a freed array leaves the resident set at once."""
    with build_arrays():
        scratch = np.empty(2 << 20)  # raise the heap's threshold as a build's temporaries do
        del scratch
        a = np.ones(2 << 20)  # 16 MiB
        held = resident_mib()
        del a
    assert held - resident_mib() > 14


def test_it_maps_on_linux():
    assert pages.MAPS == sys.platform.startswith("linux")


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or not os.path.exists("/proc/self/statm") or not pages.MAPS,
    reason="glibc's heap, read from /proc",
)
def test_trim_heap_hands_back_what_the_kernels_scratch_left():
    """The BRIO order mallocs two scratch arrays of n items: once glibc has raised its threshold for
    mapping such blocks (a first large block freed), the next ones stay in its heap when freed, resident,
    until trim_heap hands them back."""
    from tvoronoi.kernels import order

    xs, ys = generate("uniform", 600_000, seed=5).T.copy()
    for _ in range(3):  # 14 MiB of items twice each time: the first frees mappings, the next stay in the heap
        order.brio_order(xs, ys, 0)
    pages.trim_heap()
    floor = resident_mib()
    order.brio_order(xs, ys, 0)
    kept = resident_mib() - floor
    pages.trim_heap()
    assert kept > 3, f"the scratch left {kept:.1f} MiB: glibc handed it back by itself"
    assert resident_mib() - floor < 1, f"{kept:.0f} MiB stayed after the order, and trim_heap kept them"


def data_address(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


@pytest.mark.skipif(not pages.MAPS, reason="no mappings here")
def test_a_freed_mapping_is_given_to_the_next_array_and_zeros_are_zeros():
    """Within a build, a freed mapping is kept and reused (its pages are resident already); a reused one
    that numpy asks to be zero is zero, including its grown part."""
    with build_arrays():
        a = np.full(BIG * 4, 7.0)
        where = data_address(a)
        del a
        b = np.empty(BIG * 4)
        assert data_address(b) == where  # the same pages, no new mapping
        b[:] = 3.0
        del b
        z = np.zeros(BIG * 4)
        assert data_address(z) == where and not z.any()
        del z
        g = np.zeros(BIG * 9)  # grown in place or moved with its pages, the new part fresh
        assert not g.any()
        g[:] = 1.0
        del g
        s = np.zeros(BIG + 5)  # cut down to size
        assert not s.any()


@pytest.mark.skipif(not pages.MAPS or not os.path.exists("/proc/self/statm"), reason="no mappings here")
def test_kept_mappings_are_handed_back_when_the_build_ends():
    """At most 32 MiB of freed mappings are kept, and only until the build's block ends."""
    with build_arrays():
        a = np.ones(2 << 20)  # 16 MiB, kept once freed
        del a
        held = resident_mib()
        big = [np.ones(2 << 20) for _ in range(4)]  # 64 MiB: the kept one reused, the others new
        del big  # 32 MiB kept at most: the rest unmapped at once
        assert resident_mib() - held < 40
    assert held - resident_mib() > 14


def test_threads_allocating_at_once_keep_their_data():
    """Both halves of a build allocate and free at once: the kept mappings are shared under a lock."""
    errors: list[str] = []

    def churn(seed: int) -> None:
        rng = np.random.default_rng(seed)
        for _ in range(60):
            n = int(rng.integers(BIG, 6 * BIG))
            a = np.full(n, float(seed))
            b = np.zeros(n // 2)
            if not (a == seed).all() or b.any():
                errors.append(f"thread {seed}: data changed")
            del a, b

    with build_arrays():
        import contextvars

        workers = [threading.Thread(target=contextvars.copy_context().run, args=(churn, s)) for s in (1, 2, 3)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()
    assert not errors


@pytest.mark.skipif(not pages.MAPS, reason="no mappings here")
@pytest.mark.parametrize("mib", [4, 5, 24, 33])
def test_a_fresh_large_mapping_starts_on_a_huge_page(mib):
    """From 4 MiB on, a fresh mapping starts on a 2 MiB boundary (the array 64 bytes after it, its
    header), so that every whole huge page of it can be one; nothing beyond its pages stays mapped
    (the slack taken to align it is handed back), and it is writable to its last byte."""
    with build_arrays():
        held = resident_mib()
        a = np.empty((mib << 20) // 8)
        assert data_address(a) % (2 << 20) == 64
        a[:] = 1.0
        assert a[-1] == 1.0 and a.sum() == a.size
        assert resident_mib() - held < mib + 2.5
        del a


def kernel_at_least(major: int, minor: int) -> bool:
    """The running kernel (Linux) is at least major.minor."""
    release = os.uname().release.split("-")[0].split(".")
    try:
        return (int(release[0]), int(release[1])) >= (major, minor)
    except (IndexError, ValueError):
        return False


# (MADV_POPULATE_WRITE came with Linux 5.14; before it, populate leaves the pages to their first stores)
@pytest.mark.skipif(not pages.MAPS or not kernel_at_least(5, 14), reason="no mappings or no populate here")
def test_populated_pages_become_resident_and_keep_their_data():
    """populate (the kernels' call before writing an array whole) makes a fresh array's pages resident
    in one call, and changes nothing already written: a part written before it keeps its values, a
    part never written stays zero."""
    with build_arrays():
        held = resident_mib()
        a = np.zeros((24 << 20) // 4, np.int32)  # fresh pages: not resident until touched
        assert resident_mib() - held < 4
        a[: a.size // 3] = np.arange(a.size // 3, dtype=np.int32)
        pages.populate_pages(a)
        assert resident_mib() - held > 22
        assert np.array_equal(a[: a.size // 3], np.arange(a.size // 3, dtype=np.int32))
        assert not a[a.size // 3 :].any()
        with pytest.raises(ValueError, match="C-contiguous"):
            pages.populate_pages(a[::2])
        del a


def advised_for_huge_pages(a: np.ndarray) -> bool:
    """Whether the mapping holding a's data carries MADV_HUGEPAGE (VmFlags hg in /proc/self/smaps)."""
    address = data_address(a)
    inside = False
    with open("/proc/self/smaps") as f:
        for line in f:
            head = line.split()[0]
            if "-" in head and not head.endswith(":"):
                lo, hi = (int(v, 16) for v in head.split("-"))
                inside = lo <= address < hi
            elif inside and head == "VmFlags:":
                return "hg" in line.split()[1:]
    raise AssertionError("no mapping holds the array")


@pytest.mark.skipif(not pages.MAPS or not os.path.exists("/proc/self/smaps"), reason="no mappings here")
def test_small_pages_leaves_fresh_mappings_unadvised_in_its_thread_only():
    """Inside pages.small_pages() a fresh mapping of 8 MiB is not advised for huge pages; outside it, and
    in another thread meanwhile, it is, as before; the block ends as it began, on an exception too.
    (Each array is held: a freed one would be kept and given to the next, advice and all.)"""
    seen: dict[str, bool] = {}

    def other() -> None:
        with build_arrays():
            mine = np.empty(1 << 20)
            seen["other"] = advised_for_huge_pages(mine)

    with build_arrays():
        held = [np.empty(1 << 20)]
        assert advised_for_huge_pages(held[0])
        with pages.small_pages():
            small = np.empty(1 << 20)
            assert not advised_for_huge_pages(small)
            worker = threading.Thread(target=other)
            worker.start()
            worker.join()
            small[:] = 2.0
            assert small.sum() == 2.0 * small.size
        assert seen["other"]
        with pytest.raises(RuntimeError), pages.small_pages():
            raise RuntimeError("left")
        held.append(np.empty(1 << 20))
        assert advised_for_huge_pages(held[-1])
