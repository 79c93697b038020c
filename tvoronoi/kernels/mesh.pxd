# The triangulation shared by the incremental engine and the dynamic diagrams: its layout and the
# small helpers every phase uses. The phases of an insertion live beside it: location.pxd (walk or
# conflict list to a triangle in conflict), cavity.pxd (the conflict region), fill.pxd (the fan).
# Inline functions, compiled into each kernel that cimports them (the insertion loop is hot, and
# Cython shares cdef functions across modules only through pointers).

from libc.stdint cimport int32_t

# Layout of a triangulation (struct of arrays, like delaunator):
#   triangle t owns half-edges 3t, 3t+1, 3t+2, counter-clockwise;
#   tv[e]  the vertex half-edge e starts from (it ends at tv[nxt(e)]),
#   opp[e] the twin half-edge, in the neighbouring triangle.
# The hull is closed by one vertex at infinity, numbered n (the site count):
# every hull edge u->w (interior on its left) has an "infinite triangle"
# (w, u, inf) on its other side, so that every half-edge has a twin and
# insertion outside the hull is the same cavity operation as inside.
# A triangulation of n sites plus the vertex at infinity has 2n - 2 triangles.


cdef inline int nxt(int e) noexcept nogil:
    return e - 2 if e % 3 == 2 else e + 1


cdef inline int prv(int e) noexcept nogil:
    return e + 2 if e % 3 == 0 else e - 1


cdef struct Mesh:
    const double* x
    const double* y
    int32_t* tv
    int32_t* opp
    int32_t* vmap       # per vertex: the new triangle whose cavity-boundary edge starts there
    int32_t* cavity     # triangles of the current cavity
    int32_t* cav_from   #   and for each, its half-edge back to the cavity triangle it was reached from
    int32_t* bnd_a      # cavity boundary edges a->b and the outside twin half-edge
    int32_t* bnd_b
    int32_t* bnd_twin
    int32_t* head       # conflict lists (textbook order): first waiting site per triangle
    int32_t* next_site  #   and the next one in the same list
    int32_t* where      #   and the triangle each waiting site is listed under (-1 once inserted)
    int32_t* dup        # per site: the earlier site at the same place, or -1
    int32_t* trace_cav  # step trace only (else NULL): the last cavity's triangles, as vertex triples
    int trace_n_cav
    int32_t* trace_new  #   and the slots of the triangles that replaced them
    int trace_n_new
    # dynamic diagrams only (else NULL): free triangle slots, one half-edge out of
    # each vertex, and the sites whose cells the last insertion changed
    int32_t* free_tri
    int n_free
    int32_t* vedge
    int32_t* changed
    int n_changed
    int32_t* jump_grid  # dynamic diagrams: a recent site in each cell of a g x g grid over the sites
    int jump_g          #   (location.jump_start), its size, origin and cells per unit
    double jump_x0
    double jump_y0
    double jump_sx
    double jump_sy
    int walk_steps      # triangles the last walk visited (for tests)
    int n_finite        # finite triangles (kept up to date only where vedge is kept)
    int n
    int inf
    int vmap_inf        # vmap's entry for the vertex at infinity
    int n_tri
    int last            # a recently created finite triangle: where walks start
    int n_cav           # the last cavity found: its triangles and boundary edges
    int n_bnd


cdef inline bint is_infinite(Mesh* m, int t) noexcept nogil:
    return m.tv[3 * t] == m.inf or m.tv[3 * t + 1] == m.inf or m.tv[3 * t + 2] == m.inf


cdef inline bint strictly_between(Mesh* m, int u, int w, double px, double py) noexcept nogil:
    """p, already known collinear with u and w, lies strictly inside segment uw."""
    cdef double ux = m.x[u], uy = m.y[u], wx = m.x[w], wy = m.y[w]
    if ux != wx:
        return (ux < px < wx) or (wx < px < ux)
    return (uy < py < wy) or (wy < py < uy)
