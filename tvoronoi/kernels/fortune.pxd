# Fortune's sweep, for other kernels: a C entry over a few sites (local updates of dynamic diagrams).

from libc.stdint cimport int32_t

cdef int sweep_triangles(const double* x, const double* y, int n, int32_t* tv_out, int cap) noexcept nogil
