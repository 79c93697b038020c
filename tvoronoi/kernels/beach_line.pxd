# Fortune's beach line (fortune.pyx): the arcs left to right, as an AVL tree (in the Sweep's arrays) and a
# doubly linked list; positions are given, never searched by key, except where a new site is located
# (exactly: parabola_order and coordinate comparisons), by a short walk along the list from a hint, else
# down the tree. Inline helpers, compiled into the fortune module.

from libc.stdint cimport int8_t

from tvoronoi.kernels.parabola cimport parabola_order
from tvoronoi.kernels.sweep_state cimport Sweep, NONE

# ---------------------------------------------------------------------------------------------------------
# the AVL tree of arcs

cdef inline int h_of(Sweep* s, int v) noexcept nogil:
    return 0 if v == NONE else s.height[v]


cdef inline void fix_height(Sweep* s, int v) noexcept nogil:
    cdef int hl = h_of(s, s.left[v]), hr = h_of(s, s.right[v])
    s.height[v] = <int8_t>(1 + (hl if hl > hr else hr))


cdef inline void replace_child(Sweep* s, int p, int old, int new) noexcept nogil:
    if p == NONE:
        s.root = new
    elif s.left[p] == old:
        s.left[p] = new
    else:
        s.right[p] = new


cdef inline int rotate_left(Sweep* s, int x) noexcept nogil:
    cdef int y = s.right[x]
    s.right[x] = s.left[y]
    if s.left[y] != NONE:
        s.parent[s.left[y]] = x
    s.parent[y] = s.parent[x]
    replace_child(s, s.parent[x], x, y)
    s.left[y] = x
    s.parent[x] = y
    fix_height(s, x)
    fix_height(s, y)
    return y


cdef inline int rotate_right(Sweep* s, int x) noexcept nogil:
    cdef int y = s.left[x]
    s.left[x] = s.right[y]
    if s.right[y] != NONE:
        s.parent[s.right[y]] = x
    s.parent[y] = s.parent[x]
    replace_child(s, s.parent[x], x, y)
    s.right[y] = x
    s.parent[x] = y
    fix_height(s, x)
    fix_height(s, y)
    return y


cdef inline void rebalance_up(Sweep* s, int v) noexcept nogil:
    cdef int bal, before
    while v != NONE:
        before = s.height[v]
        fix_height(s, v)
        bal = h_of(s, s.left[v]) - h_of(s, s.right[v])
        if -1 <= bal <= 1 and s.height[v] == before:
            return          # this subtree's height did not change: nothing above it did

        if bal > 1:
            if h_of(s, s.left[s.left[v]]) < h_of(s, s.right[s.left[v]]):
                rotate_left(s, s.left[v])
            v = rotate_right(s, v)
        elif bal < -1:
            if h_of(s, s.right[s.right[v]]) < h_of(s, s.left[s.right[v]]):
                rotate_right(s, s.right[v])
            v = rotate_left(s, v)
        v = s.parent[v]


cdef inline int new_arc(Sweep* s, int site) noexcept nogil:
    cdef int a
    if s.n_free > 0:
        s.n_free -= 1
        a = s.free_arcs[s.n_free]
    else:
        a = s.n_arcs
        s.n_arcs += 1
    s.arc_site[a] = site
    s.arc_prev[a] = NONE
    s.arc_next[a] = NONE
    s.left[a] = NONE
    s.right[a] = NONE
    s.parent[a] = NONE
    s.height[a] = 1
    s.arc_event[a] = NONE
    s.arc_edge[a] = NONE
    return a


cdef inline void insert_after(Sweep* s, int x, int z) noexcept nogil:
    """Put arc z right after arc x, in the list and in the tree."""
    cdef int y
    s.arc_prev[z] = x
    s.arc_next[z] = s.arc_next[x]
    if s.arc_next[x] != NONE:
        s.arc_prev[s.arc_next[x]] = z
    s.arc_next[x] = z
    if s.right[x] == NONE:
        s.right[x] = z
        s.parent[z] = x
    else:
        y = s.right[x]
        while s.left[y] != NONE:
            y = s.left[y]
        s.left[y] = z
        s.parent[z] = y
    rebalance_up(s, s.parent[z])


cdef inline void remove_arc(Sweep* s, int z) noexcept nogil:
    """Take arc z out of the list and the tree."""
    cdef int y, zp, zl, zr, yp, yr, child, p
    cdef int8_t zh
    if s.arc_prev[z] != NONE:
        s.arc_next[s.arc_prev[z]] = s.arc_next[z]
    else:
        s.first_arc = s.arc_next[z]
    if s.arc_next[z] != NONE:
        s.arc_prev[s.arc_next[z]] = s.arc_prev[z]
    if s.left[z] != NONE and s.right[z] != NONE:
        # swap z with its successor y in the tree (y has no left child)
        y = s.right[z]
        while s.left[y] != NONE:
            y = s.left[y]
        zp = s.parent[z]; zl = s.left[z]; zr = s.right[z]; zh = s.height[z]
        yp = s.parent[y]; yr = s.right[y]
        replace_child(s, zp, z, y)
        s.parent[y] = zp
        s.left[y] = zl
        s.parent[zl] = y
        if yp == z:
            s.right[y] = z
            s.parent[z] = y
        else:
            s.right[y] = zr
            s.parent[zr] = y
            s.left[yp] = z
            s.parent[z] = yp
        s.left[z] = NONE
        s.right[z] = yr
        if yr != NONE:
            s.parent[yr] = z
        s.height[z] = s.height[y]
        s.height[y] = zh
    child = s.left[z] if s.left[z] != NONE else s.right[z]
    p = s.parent[z]
    replace_child(s, p, z, child)
    if child != NONE:
        s.parent[child] = p
    rebalance_up(s, p)
    s.arc_site[z] = NONE
    s.free_arcs[s.n_free] = z
    s.n_free += 1


# ---------------------------------------------------------------------------------------------------------
# locating a new site on the beach line

cdef inline int breakpoint_side(Sweep* s, int a, int b, double px, double py) noexcept nogil:
    """-1 if p is left of the breakpoint between arcs of sites a (left) and b, +1 right, 0 on it."""
    cdef double ax = s.x[a], ay = s.y[a], bx = s.x[b], by = s.y[b]
    cdef int o
    # of two parabolas, the narrower (its site nearer the sweep line) is above the
    # other between their two crossings, and its apex lies between them: the
    # breakpoint with a on the left is the right crossing if a is narrower
    if ay > by:
        if px <= ax:
            return -1
    elif by > ay:
        if px >= bx:
            return 1
    elif ay == py:
        return 1          # degenerate case: both on the sweep row; p comes after them
    o = parabola_order(ax, ay, bx, by, px, py)
    return -1 if o > 0 else (1 if o < 0 else 0)


cdef enum:
    WALK_MAX = 8        # arcs a walk from a hint may pass before the tree is searched instead
    HINTS_TRIAL = 2048  # sites searched in the tree before the hints may be given up (most sites were)


cdef inline int hint_slot(Sweep* s, double px) noexcept nogil:
    """The strip of x that px lies in (0 .. n_hint - 1)."""
    cdef double f = (px - s.hint_x0) * s.hint_scale
    if not (f >= 0.0):
        return 0
    if f >= s.n_hint - 1:
        return s.n_hint - 1
    return <int> f


cdef inline void set_hint(Sweep* s, double x, int arc) noexcept nogil:
    """Arc (live) is where a site at x would be located now, or near it."""
    cdef int k
    if s.n_hint == 0:
        return              # no hints: every site down the tree
    k = hint_slot(s, x)
    s.hint[k] = arc
    s.hint_site[k] = s.arc_site[arc]


cdef inline int walk_to_arc(Sweep* s, int h, double px, double py) noexcept nogil:
    """The arc above p by a walk along the beach line from the live arc h: the arc whose breakpoints
    have p strictly between them; NONE when p lies on a breakpoint, or further than WALK_MAX arcs.

    Strictly between its breakpoints, the arc is the only one that locate_arc can return (the
    breakpoints are in order along the line), so either way gives the same arc. At a breakpoint the
    tree's search decides, as it always has.
    """
    cdef int a, c, k, side
    # (a step left shows that p is left of the new arc's right breakpoint, a step right that it is right
    # of its left one: neither is tested again)
    cdef bint left_known = False, right_known = False
    for k in range(WALK_MAX):
        a = s.arc_prev[h]
        if a != NONE and not left_known:
            side = breakpoint_side(s, s.arc_site[a], s.arc_site[h], px, py)
            if side < 0:
                h = a
                right_known = True
                continue
            if side == 0:
                return NONE
        c = s.arc_next[h]
        if c != NONE and not right_known:
            side = breakpoint_side(s, s.arc_site[h], s.arc_site[c], px, py)
            if side > 0:
                h = c
                left_known = True
                continue
            if side == 0:
                return NONE
        return h
    return NONE


cdef inline int locate_hinted(Sweep* s, double px, double py) noexcept nogil:
    """locate_arc, by a walk from the hint of p's strip (else of a strip beside it) when it holds a live
    arc and the walk settles; else down the tree. Counts each way in n_walks and n_descents, and gives
    the hints up (n_hint = 0) once the tree has located more sites than the walks, past HINTS_TRIAL."""
    cdef int k, h, v
    if s.n_hint == 0:
        s.n_descents += 1
        return locate_arc(s, px, py)
    k = hint_slot(s, px)
    h = s.hint[k]
    if h == NONE or s.arc_site[h] != s.hint_site[k]:
        # a stale hint: the next strip's, else the one before's
        if k + 1 < s.n_hint and s.hint[k + 1] != NONE and s.arc_site[s.hint[k + 1]] == s.hint_site[k + 1]:
            h = s.hint[k + 1]
        elif k > 0 and s.hint[k - 1] != NONE and s.arc_site[s.hint[k - 1]] == s.hint_site[k - 1]:
            h = s.hint[k - 1]
        else:
            h = NONE
    if h != NONE:
        v = walk_to_arc(s, h, px, py)
        if v != NONE:
            s.n_walks += 1
            return v
    s.n_descents += 1
    if s.n_descents > HINTS_TRIAL and s.n_descents > s.n_walks:
        s.n_hint = 0        # the strips do not fit these sites (clusters far apart): the tree alone from now
    return locate_arc(s, px, py)


cdef inline int locate_arc(Sweep* s, double px, double py) noexcept nogil:
    """The arc above p (at a breakpoint: the arc right of it)."""
    cdef int v = s.root, a, c, step
    while True:
        a = s.arc_prev[v]
        c = s.arc_next[v]
        step = 0
        if a != NONE and breakpoint_side(s, s.arc_site[a], s.arc_site[v], px, py) < 0:
            step = -1
        elif c != NONE and breakpoint_side(s, s.arc_site[v], s.arc_site[c], px, py) > 0:
            step = 1
        if step == -1 and s.left[v] != NONE:
            v = s.left[v]
        elif step == 1 and s.right[v] != NONE:
            v = s.right[v]
        else:
            return v
