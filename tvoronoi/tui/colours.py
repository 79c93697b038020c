"""Cell colours: palettes for dark and light themes, and a colouring in which neighbours differ."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Every planar graph has a vertex of degree <= 5, so peeling such vertices and
# colouring them back in reverse never meets more than 5 coloured neighbours:
# 6 colours suffice, and a palette of 8 leaves room to spread them.
PLANAR_DEGENERACY = 5
# Fixed seed of the tie-breaking priorities: the same diagram is always coloured the same way.
PRIORITY_SEED = 0x7F4A7C15
# Multiplier that scatters each cell's first-choice colour over the palette (a golden-ratio step).
SCATTER = 0x9E3779B1
# Colour masks are one byte: at most 8 colours.
MAX_COLOURS = 8


@dataclass(frozen=True)
class Palette:
    """The colours of one theme: muted cell fills and the marks drawn over them."""

    fills: tuple[str, ...]
    edge: str
    site: str
    vertex: str
    delaunay: str


# All colours are exact entries of the xterm 256-colour cube, so a terminal (or a
# tmux over SSH) that has only 256 colours shows the same 8 distinct fills.

# Muted mid-dark fills: light edges and bright marks stay readable on each of them.
DARK = Palette(
    fills=(
        "#5f5f87",  # slate
        "#5f875f",  # sage
        "#875f5f",  # rosewood
        "#5f8787",  # grey teal
        "#87875f",  # olive
        "#875f87",  # mauve
        "#005f87",  # deep sky
        "#875f00",  # umber
    ),
    edge="#eeeeee",
    site="#ffd75f",
    vertex="#ff8787",
    delaunay="#87d7d7",
)

# Pastel fills: dark edges and deep marks stay readable on each of them.
LIGHT = Palette(
    fills=(
        "#afafd7",  # lavender
        "#afd7af",  # pale green
        "#d7afaf",  # pale rose
        "#afd7d7",  # pale cyan
        "#d7d7af",  # khaki
        "#d7afd7",  # orchid
        "#87afd7",  # steel blue
        "#d7af87",  # tan
    ),
    edge="#1c1c1c",
    site="#af0000",
    vertex="#5f00af",
    delaunay="#005f5f",
)


def palette_for(dark: bool) -> Palette:
    """The palette that reads on a dark (True) or light (False) theme."""
    return DARK if dark else LIGHT


def cell_adjacency(diagram) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of neighbouring cells of a diagram, each pair once.

    Cells f and g are neighbours when a Voronoi edge separates them: some
    half-edge e has ``he_face[e] == f`` and ``he_face[he_twin[e]] == g``.

    Returns
    -------
    (a, b) : two (k,) int64 arrays with ``a < b``.
    """
    faces = np.asarray(diagram.he_face, np.int64)
    twins = np.asarray(diagram.he_twin, np.int64)
    keep = (twins >= 0) & (faces >= 0)
    a = faces[keep]
    b = faces[twins[keep]]
    keep = (b >= 0) & (a != b)
    a, b = a[keep], b[keep]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    n = max(int(diagram.n_sites), 1)
    # each edge comes twice (a half-edge and its twin): sort and keep one of each
    key = np.sort(lo * n + hi)
    key = key[np.r_[True, key[1:] != key[:-1]]] if key.size else key
    return key // n, key % n


def colour_graph(n: int, a: np.ndarray, b: np.ndarray, n_colours: int = MAX_COLOURS) -> np.ndarray:
    """Colour the vertices of a planar graph so that no edge joins two equal colours.

    Vectorised greedy colouring in a degeneracy order: peel every vertex of
    degree <= 5 in rounds, then colour the rounds back from the last one. In a
    round, the vertices whose uncoloured round-neighbours all have a lower
    (random, seeded) priority are coloured together. Each vertex then sees at
    most 5 coloured neighbours and takes a free colour, trying first a colour
    scattered by its number so that the whole palette gets used.

    Parameters
    ----------
    n : int
        Number of vertices.
    a, b : (k,) int arrays
        The edges, each given once (either direction).
    n_colours : int
        Size of the palette, 6 to 8 for the guarantee.

    Returns
    -------
    (n,) int8 colours in ``0 .. n_colours - 1``. No edge joins equal colours
    in a planar graph; a graph that is not planar may have clashes.

    >>> a, b = [0, 1, 2, 3, 0], [1, 2, 3, 0, 2]  # a square and one diagonal
    >>> c = colour_graph(4, a, b)
    >>> bool((c[a] != c[b]).all())
    True
    """
    if not 1 <= n_colours <= MAX_COLOURS:
        raise ValueError(f"n_colours must be 1 to {MAX_COLOURS}, got {n_colours}")
    index = np.int32 if n < np.iinfo(np.int32).max else np.int64
    a = np.asarray(a).astype(index, copy=False)
    b = np.asarray(b).astype(index, copy=False)
    # peel the vertices of low degree, a whole round at once
    round_of = np.full(n, -1, np.int32)
    alive = np.ones(n, bool)
    deg = np.bincount(a, minlength=n) + np.bincount(b, minlength=n)
    live_a, live_b = a, b
    n_rounds = 0
    while alive.any():
        peel = alive & (deg <= PLANAR_DEGENERACY)
        if not peel.any():
            # not planar (a Voronoi diagram never gets here): peel the least connected
            peel = alive & (deg == deg[alive].min())
        round_of[peel] = n_rounds
        alive &= ~peel
        keep_a, keep_b = alive[live_a], alive[live_b]
        # an edge that lost one end lowers the degree of the other
        deg -= np.bincount(live_b[keep_b & ~keep_a], minlength=n)
        deg -= np.bincount(live_a[keep_a & ~keep_b], minlength=n)
        keep = keep_a & keep_b
        live_a, live_b = live_a[keep], live_b[keep]
        n_rounds += 1

    priority = np.random.default_rng(PRIORITY_SEED).permutation(n).astype(index)
    first_choice = (np.arange(n, dtype=np.uint64) * np.uint64(SCATTER) >> np.uint64(16)) % np.uint64(n_colours)
    first_choice = first_choice.astype(np.int64)
    full = (1 << n_colours) - 1
    colour = np.full(n, -1, np.int8)
    taken = np.zeros(n, np.uint8)  # bit c set: a coloured neighbour has colour c
    # an edge between rounds matters only to its end peeled first (coloured later);
    # an edge inside a round matters to both ends
    ra, rb = round_of[a], round_of[b]
    cross = ra != rb
    owner = np.where(ra < rb, a, b)[cross]
    other = np.where(ra < rb, b, a)[cross]
    owner_round = np.minimum(ra, rb)[cross]
    inner = ~cross
    in_src = np.concatenate([a[inner], b[inner]])
    in_dst = np.concatenate([b[inner], a[inner]])
    in_round = round_of[in_src]

    # colour the rounds back, the last peeled first
    for k in range(n_rounds - 1, -1, -1):
        members = np.flatnonzero(round_of == k)
        # neighbours in later rounds are coloured for good: note their colours once
        mine = owner_round == k
        _add_colours(taken, owner[mine], colour[other[mine]], n_colours)
        # neighbours in this round: es waits for ed while ed is uncoloured and goes first
        mine = in_round == k
        es, ed = in_src[mine], in_dst[mine]
        first = priority[ed] > priority[es]
        wait_s, wait_d = es[first], ed[first]
        while members.size:
            blocked = np.zeros(n, bool)
            blocked[wait_s[colour[wait_d] < 0]] = True
            ready = members[~blocked[members]]
            # the free colour nearest after the scattered first choice
            used = taken[ready].astype(np.int64) & full
            off = first_choice[ready]
            rotated = ((used >> off) | (used << (n_colours - off))) & full
            free = ~rotated & (rotated + 1)
            pick = (_lowest_bit(free) + off) % n_colours
            # every colour taken (not planar): keep the first choice and accept the clash
            crowded = rotated == full
            pick[crowded] = off[crowded]
            colour[ready] = pick
            # tell the neighbours in this round what was just taken
            just = np.zeros(n, bool)
            just[ready] = True
            told = just[ed]
            _add_colours(taken, es[told], colour[ed[told]], n_colours)
            members = members[~just[members]]
            left = ~just[es] & ~told
            es, ed = es[left], ed[left]
            left = ~just[wait_s]
            wait_s, wait_d = wait_s[left], wait_d[left]
    return colour


def _add_colours(taken: np.ndarray, owners: np.ndarray, colours: np.ndarray, n_colours: int) -> None:
    """Set bit ``colours[j]`` of ``taken[owners[j]]`` for every j (owners may repeat)."""
    for c in range(n_colours):
        # repeated owners all write the same value, so one fancy-index update is exact
        taken[owners[colours == c]] |= np.uint8(1 << c)


def _lowest_bit(x: np.ndarray) -> np.ndarray:
    """Index of the single set bit of each power of two in x."""
    return np.log2(x.astype(np.float64)).astype(np.int64)


def cell_colours(diagram, n_colours: int = MAX_COLOURS) -> np.ndarray:
    """A palette index for every cell of a diagram, different across every Voronoi edge.

    Returns
    -------
    (n,) int8 in ``0 .. n_colours - 1``; a repeated point takes the colour of
    its first copy.
    """
    n = int(diagram.n_sites)
    a, b = cell_adjacency(diagram)
    colour = colour_graph(n, a, b, n_colours)
    return colour[np.asarray(diagram.site_of, np.int64)]
