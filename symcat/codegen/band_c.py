"""The LU factorization without pivoting of a band matrix and its solve as C loops, for the
compiled generalized-alpha steps (:mod:`symcat.integrate.bordered_band`; row-major,
:func:`band_functions`, or column-major over the envelope, :func:`envelope_functions`, which
the steps use); with the other hand-written kernels of those steps: dense products
(:func:`matvec`) and stores into the caller's memory (:func:`store_function`); the wires'
sparse products and scatters are :mod:`.sparse_c`'s, whose sources :func:`include_in` appends
too.

Why: as CasADi SX graphs both are straight-line code, one instruction per operation: for a
wire of 60 cable elements (360 unknowns, half-bandwidth 11) 1.5 MB of machine code for the
factorization and 250 kB for a solve, which with the wires' residual (700 kB) no longer fit
the processor's caches: each Newton iteration streams its code from memory. As loops they are
a few hundred bytes and do the same operations in the same order (the same results, bit for
bit: a structurally zero entry that the graph leaves out is a zero here, and subtracting a
product with a zero changes nothing).

The functions are external to CasADi: each is compiled into a small library of its own
(cached, for graphs evaluated in Python), and code generated from a graph that calls them
must include their C source (:func:`include_in` appends it): CasADi's generated code declares
and calls them by name.
"""
from __future__ import annotations

import os
import re
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path

import casadi as ca
from .library import build_library, cached_library, find_compiler

#: Flags of the kernels' own library (the code generated around them has its own).
FLAGS = ("-O2", "-fPIC", "-shared")

_TEMPLATE = r"""
/* symcat band kernels: n = {n}, half-bandwidth {bw} (symcat.codegen.band_c) */
#ifndef casadi_real
#define casadi_real double
#endif
#ifndef casadi_int
#define casadi_int long long int
#endif
static const casadi_int {lu}_sp[] = {{{size}, 1, 1}};  /* dense (CasADi's compact form) */
static const casadi_int {solve}_sp[] = {{{n}, 1, 1}};

/* band -> lu: row-major band storage, a[i][j] at i (2 bw + 1) + j - i + bw; L unit lower
   below the diagonal, U on and above it */
int {lu}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  const casadi_int n = {n}, bw = {bw}, wd = 2 * {bw} + 1;
  casadi_int i, j, k, end;
  casadi_real *a = res[0], inv, lik;
  if (!a) return 0;
  for (i = 0; i < n * wd; ++i) a[i] = arg[0] ? arg[0][i] : 0;
  for (k = 0; k < n; ++k) {{
    inv = 1 / a[k * wd + bw];
    end = k + bw + 1 < n ? k + bw + 1 : n;
    for (i = k + 1; i < end; ++i) {{
      lik = a[i * wd + k - i + bw] * inv;
      a[i * wd + k - i + bw] = lik;
      for (j = k + 1; j < end; ++j) a[i * wd + j - i + bw] -= lik * a[k * wd + j - k + bw];
    }}
  }}
  return 0;
}}

/* (lu, b) -> x: L z = b, then U x = z, by columns: each unknown once known is taken out of
   the next bw equations (independent updates, where the rows' sums would be a chain of
   dependent ones); a[i][j] at lu[i (wd - 1) + j + bw] */
int {solve}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  const casadi_int n = {n}, bw = {bw}, wd = 2 * {bw} + 1;
  casadi_int i, j, end;
  const casadi_real *restrict lu = arg[0], *restrict b = arg[1];
  casadi_real *restrict x = res[0], xj;
  if (!x) return 0;
  for (i = 0; i < n; ++i) x[i] = b ? b[i] : 0;
  for (j = 0; j < n; ++j) {{
    xj = x[j];
    end = j + bw + 1 < n ? j + bw + 1 : n;
    for (i = j + 1; i < end; ++i) x[i] -= lu[i * (wd - 1) + j + bw] * xj;
  }}
  for (j = n - 1; j >= 0; --j) {{
    xj = x[j] /= lu[j * (wd - 1) + j + bw];
    for (i = j - bw > 0 ? j - bw : 0; i < j; ++i) x[i] -= lu[i * (wd - 1) + j + bw] * xj;
  }}
  return 0;
}}

casadi_int {lu}_n_in(void) {{ return 1; }}
casadi_int {lu}_n_out(void) {{ return 1; }}
const casadi_int* {lu}_sparsity_in(casadi_int i) {{ return {lu}_sp; }}
const casadi_int* {lu}_sparsity_out(casadi_int i) {{ return {lu}_sp; }}
casadi_int {solve}_n_in(void) {{ return 2; }}
casadi_int {solve}_n_out(void) {{ return 1; }}
const casadi_int* {solve}_sparsity_in(casadi_int i) {{ return i == 0 ? {lu}_sp : {solve}_sp; }}
const casadi_int* {solve}_sparsity_out(casadi_int i) {{ return {solve}_sp; }}
"""



_ENVELOPE = r"""
/* symcat envelope band kernels: n = {n}, half-bandwidth {bw} (symcat.codegen.band_c) */
#ifndef casadi_real
#define casadi_real double
#endif
#ifndef casadi_int
#define casadi_int long long int
#endif
static const casadi_int {lu}_sp[2][3] = {{{{{band}, 1, 1}}, {{{size}, 1, 1}}}};
static const casadi_int {solve}_sp[] = {{{n}, 1, 1}};

/* band -> factor: column-major band storage, a[i][j] at j (2 bw + 1) + i - j + bw; L unit
   lower below the diagonal, U on and above it; then per column k the last row of L's column
   (last[k]) and the first row of U's (top[k]), as numbers. Only the envelope is visited: row
   i from its first nonzero, column j from its first nonzero (from the values: an entry that
   is zero outside them stays zero, its products with the pivots' rows and columns zeros). */
int {lu}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  const casadi_int n = {n}, bw = {bw}, wd = 2 * {bw} + 1;
  casadi_int i, j, k, lo, end, right;
  casadi_real *a = res[0], *last, *top, inv, ukj;
  casadi_real *restrict ck, *restrict cj;
  if (!a) return 0;
  last = a + n * wd, top = last + n;
  for (i = 0; i < n * wd; ++i) a[i] = arg[0] ? arg[0][i] : 0;
  for (k = 0; k < n; ++k) last[k] = top[k] = k;
  for (j = 0; j < n; ++j) {{  /* the first nonzero of column j above the diagonal */
    for (i = j - bw > 0 ? j - bw : 0; i < j; ++i) if (a[j * wd + i - j + bw] != 0) break;
    top[j] = i;
  }}
  for (i = 0; i < n; ++i) {{  /* row i's first nonzero left of the diagonal: L's columns reach row i */
    for (lo = i - bw > 0 ? i - bw : 0; lo < i; ++lo) if (a[lo * wd + i - lo + bw] != 0) break;
    for (k = lo; k < i; ++k) last[k] = i;  /* (i increasing: the last such row) */
  }}
  for (k = 0; k < n; ++k) {{
    end = (casadi_int) last[k] + 1;
    for (right = k, j = k + 1; j < n && j <= k + bw; ++j) if ((casadi_int) top[j] <= k) right = j;
    ck = a + k * wd + bw - k;  /* column k: a[i][k] at ck[i] */
    inv = 1 / ck[k];
    for (i = k + 1; i < end; ++i) ck[i] *= inv;
    for (j = k + 1; j <= right; ++j) {{
      cj = a + j * wd + bw - j;
      ukj = cj[k];
      for (i = k + 1; i < end; ++i) cj[i] -= ck[i] * ukj;
    }}
  }}
  return 0;
}}

/* (factor, b) -> x: L z = b, then U x = z, by columns (each column's entries contiguous, its
   updates independent) over the envelope */
int {solve}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  const casadi_int n = {n}, bw = {bw}, wd = 2 * {bw} + 1;
  casadi_int i, j, end;
  const casadi_real *restrict lu = arg[0], *restrict b = arg[1], *last, *top, *restrict cj;
  casadi_real *restrict x = res[0], xj;
  if (!x) return 0;
  for (i = 0; i < n; ++i) x[i] = b ? b[i] : 0;
  if (!lu) return 0;
  last = lu + n * wd, top = last + n;
  for (j = 0; j < n; ++j) {{
    cj = lu + j * wd + bw - j;
    xj = x[j];
    end = (casadi_int) last[j] + 1;
    for (i = j + 1; i < end; ++i) x[i] -= cj[i] * xj;
  }}
  for (j = n - 1; j >= 0; --j) {{
    cj = lu + j * wd + bw - j;
    xj = x[j] /= cj[j];
    for (i = (casadi_int) top[j]; i < j; ++i) x[i] -= cj[i] * xj;
  }}
  return 0;
}}

casadi_int {lu}_n_in(void) {{ return 1; }}
casadi_int {lu}_n_out(void) {{ return 1; }}
const casadi_int* {lu}_sparsity_in(casadi_int i) {{ return {lu}_sp[0]; }}
const casadi_int* {lu}_sparsity_out(casadi_int i) {{ return {lu}_sp[1]; }}
casadi_int {solve}_n_in(void) {{ return 2; }}
casadi_int {solve}_n_out(void) {{ return 1; }}
const casadi_int* {solve}_sparsity_in(casadi_int i) {{ return i == 0 ? {lu}_sp[1] : {solve}_sp; }}
const casadi_int* {solve}_sparsity_out(casadi_int i) {{ return {solve}_sp; }}
"""


_MATVEC = r"""
/* symcat dense product: y = A x, A {m} x {n} column-major (symcat.codegen.band_c) */
#ifndef casadi_real
#define casadi_real double
#endif
#ifndef casadi_int
#define casadi_int long long int
#endif
static const casadi_int {name}_sp[3][3] = {{{{{size}, 1, 1}}, {{{n}, 1, 1}}, {{{m}, 1, 1}}}};

int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  casadi_int j, k;
  const casadi_real *restrict a = arg[0], *restrict x = arg[1];
  casadi_real *restrict y = res[0], acc[{m}], xk;
  if (!y) return 0;
  for (j = 0; j < {m}; ++j) acc[j] = 0;
  if (a && x) {{
    for (k = 0; k < {n}; ++k) {{
      xk = x[k];
      for (j = 0; j < {m}; ++j) acc[j] += a[j + k * {m}] * xk;
    }}
  }}
  for (j = 0; j < {m}; ++j) y[j] = acc[j];
  return 0;
}}

casadi_int {name}_n_in(void) {{ return 2; }}
casadi_int {name}_n_out(void) {{ return 1; }}
const casadi_int* {name}_sparsity_in(casadi_int i) {{ return {name}_sp[i]; }}
const casadi_int* {name}_sparsity_out(casadi_int i) {{ return {name}_sp[2]; }}
"""


_STORE = r"""
/* symcat store: {n} numbers into a caller's buffer of {size} at {at} (symcat.codegen.band_c) */
#ifndef casadi_real
#define casadi_real double
#endif
#ifndef casadi_int
#define casadi_int long long int
#endif
static const casadi_int {name}_sp[3][3] = {{{{{size}, 1, 1}}, {{{n}, 1, 1}}, {{1, 1, 1}}}};

/* (buffer, values) -> 0: the buffer is an input, written in place (its memory is the
   caller's, see store_function) */
int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  casadi_int i;
  casadi_real *buffer = (casadi_real*) arg[0];
  if (buffer && arg[1]) for (i = 0; i < {n}; ++i) buffer[{at} + i] = arg[1][i];
  if (res[0]) res[0][0] = 0;
  return 0;
}}

casadi_int {name}_n_in(void) {{ return 2; }}
casadi_int {name}_n_out(void) {{ return 1; }}
const casadi_int* {name}_sparsity_in(casadi_int i) {{ return {name}_sp[i]; }}
const casadi_int* {name}_sparsity_out(casadi_int i) {{ return {name}_sp[2]; }}
"""


def names(n: int, bw: int) -> tuple[str, str]:
    """The C names of the factorization and the solve for ``n`` unknowns, half-bandwidth ``bw``."""
    return f"symcat_band_lu_{n}_{bw}", f"symcat_band_solve_{n}_{bw}"


def source(n: int, bw: int) -> str:
    """The C source of both functions (to be included in code generated from a graph that
    calls them)."""
    lu, solve = names(n, bw)
    size = n * (2 * bw + 1)
    return _TEMPLATE.format(n=n, bw=bw, lu=lu, solve=solve, size=size)


@lru_cache(maxsize=8)
def band_functions(n: int, bw: int) -> tuple[ca.Function, ca.Function]:
    """``(lu, solve)``: ``band -> lu`` and ``(lu, b) -> x`` as CasADi externals of their own
    compiled library (cached on disk under the source's digest)."""
    lu, solve = names(n, bw)
    target = _library(source(n, bw))
    return ca.external(lu, str(target)), ca.external(solve, str(target))


def envelope_names(n: int, bw: int) -> tuple[str, str]:
    """The C names of :func:`envelope_functions`' factorization and solve."""
    return f"symcat_envband_lu_{n}_{bw}", f"symcat_envband_solve_{n}_{bw}"


def envelope_size(n: int, bw: int) -> int:
    """The size of :func:`envelope_functions`' factor: the band, then two numbers per column."""
    return n * (2 * bw + 3)


def envelope_source(n: int, bw: int) -> str:
    """The C source of :func:`envelope_functions`."""
    lu, solve = envelope_names(n, bw)
    return _ENVELOPE.format(n=n, bw=bw, lu=lu, solve=solve, band=n * (2 * bw + 1), size=envelope_size(n, bw))


@lru_cache(maxsize=8)
def envelope_functions(n: int, bw: int) -> tuple[ca.Function, ca.Function]:
    """``(lu, solve)`` as :func:`band_functions`, on a column-major band (``a[i][j]`` at
    ``j (2 bw + 1) + i - j + bw``) and over its envelope: ``band -> factor`` (the LU, then
    per column the last row of L and the first row of U that the values reach, a factor of
    :func:`envelope_size`) and ``(factor, b) -> x``.

    Why: the solve of a line's step (a few Newton iterations a step, each a solve) streams the
    factor from memory; column-major, each column's entries are contiguous (the row-major
    band's solve reads one number per cache line), and a band ordered by reverse
    Cuthill-McKee holds half of its width on average (the widest rows set the bandwidth):
    the envelope is about half the band. The operations on each entry are the row-major
    kernels', in the same order: the same numbers, bit for bit."""
    lu, solve = envelope_names(n, bw)
    target = _library(envelope_source(n, bw))
    return ca.external(lu, str(target)), ca.external(solve, str(target))


def matvec_source(m: int, n: int) -> str:
    """The C source of ``symcat_matvec_<m>_<n>``: ``(A, x) -> A x``."""
    return _MATVEC.format(name=f"symcat_matvec_{m}_{n}", m=m, n=n, size=m * n)


@lru_cache(maxsize=32)
def matvec(m: int, n: int) -> ca.Function:
    """``(A, x) -> A x`` for a dense ``m x n`` matrix ``A`` given by its column-major entries,
    as a CasADi external: the sums in CasADi's order (each row's over the columns in turn),
    in registers. CasADi's generated product accumulates through memory (``z[j] += ...``,
    whose store and reload set its speed: six microseconds for the 360 x 10 and 11 x 360
    products of a step's solve on the moving load, as long as the band's solve)."""
    return ca.external(f"symcat_matvec_{m}_{n}", str(_library(matvec_source(m, n))))


def store_source(size: int, at: int, n: int) -> str:
    """The C source of ``symcat_store_<size>_<at>_<n>``: ``(buffer, values) -> 0``."""
    return _STORE.format(name=f"symcat_store_{size}_{at}_{n}", size=size, at=at, n=n)


@lru_cache(maxsize=32)
def store_function(size: int, at: int, n: int) -> ca.Function:
    """``(buffer, values) -> token``: write the ``n`` ``values`` into ``buffer`` (``size``
    numbers) from position ``at``, in place, and give 0.

    Why: compiled steps carry a factorization of several hundred kilobytes to megabytes from
    one Newton iteration, step and call to the next; as a value of the graph every function
    that keeps it (a step that does not renew it, the steps' outputs) copies it whole. Given
    as an input whose memory the caller owns, CasADi's generated code hands its pointer on
    unchanged to every function that reads it, and this kernel writes the renewed parts
    there. Its result orders the graph: a function that reads the buffer must take the
    token of the last store as an input (CasADi evaluates a graph in the order of its data),
    and no store may be taken before a read of the values it replaces (the store's inputs
    must follow from that read's outputs). The code must be generated with the buffer read
    in place (:func:`inputs_by_reference`). The buffer is an input: evaluated by CasADi from
    Python (``DM`` arguments, copied in), the writes do not outlive the call."""
    return ca.external(f"symcat_store_{size}_{at}_{n}", str(_library(store_source(size, at, n))))


#: The size from which CasADi's generated code reads a function's input where the caller
#: holds it instead of copying it into its work vector (CasADi's global option
#: ``copy_elision_min_size``, read when the code is generated; this is its default).
REFERENCED_INPUT_SIZE = 8


@contextmanager
def inputs_by_reference():
    """Within this context a function added to a CasADi ``CodeGenerator`` (which reads the
    option then) gets code that reads every input of at least :data:`REFERENCED_INPUT_SIZE`
    numbers where its caller holds it, as :func:`store_function` needs of the buffer it
    writes (copied in, a store would be lost when the function that copied it returns)."""
    size = ca.GlobalOptions.getCopyElisionMinSize()
    ca.GlobalOptions.setCopyElisionMinSize(min(size, REFERENCED_INPUT_SIZE))
    try:
        yield
    finally:
        ca.GlobalOptions.setCopyElisionMinSize(size)


def _library(text: str) -> Path:
    """The compiled library of the C ``text`` (cached under its digest)."""
    target = cached_library("band", text.encode(), FLAGS)
    if not target.exists():
        c_path = target.with_name(f".{target.stem}-{os.getpid()}.c")
        c_path.parent.mkdir(parents=True, exist_ok=True)
        c_path.write_text(text)
        try:
            build_library(find_compiler(), FLAGS, c_path, target)
        finally:
            c_path.unlink(missing_ok=True)
    return target


#: CasADi's copy loop (``casadi_copy``), one element at a time, and what replaces it.
_COPY_LOOP = "for (i=0; i<n; ++i) *y++ = *x++;"
_COPY = "memmove(y, x, n * sizeof(casadi_real));"
#: CasADi's ``casadi_fmax`` calls the C library's ``fmax`` (not inlined without -ffast-math:
#: a call per use, a few hundred in a step's code); the same result inline: the other argument
#: when one is NaN.
_FMAX = "  return fmax(x, y);"
_FMAX_INLINE = "  return (x > y || y != y) ? x : y;"


def include_in(c_path: Path) -> Path:
    """Append to the generated ``c_path`` the source of every kernel of this module it calls
    (CasADi's code declares and calls them by name), and make its copies ``memmove``: CasADi's
    ``casadi_copy`` loop moves one number per instruction, and the compiled steps copy their
    state and a renewed factor; the C library's copy is several times faster. ``casadi_fmax`` is made inline (:data:`_FMAX`). Nothing else of the
    generated code changes."""
    text = c_path.read_text()
    if _COPY_LOOP in text:
        text = "#include <string.h>\n" + text.replace(_COPY_LOOP, _COPY)
    text = text.replace(_FMAX, _FMAX_INLINE)
    parts = [text]
    for n, bw in sorted({(int(a), int(b)) for a, b in re.findall(r"symcat_band_(?:lu|solve)_(\d+)_(\d+)\(", text)}):
        parts.append(source(n, bw))
    for n, bw in sorted({(int(a), int(b)) for a, b in re.findall(r"symcat_envband_(?:lu|solve)_(\d+)_(\d+)\(", text)}):
        parts.append(envelope_source(n, bw))
    for m, n in sorted({(int(a), int(b)) for a, b in re.findall(r"symcat_matvec_(\d+)_(\d+)\(", text)}):
        parts.append(matvec_source(m, n))
    for size, at, n in sorted({tuple(map(int, g)) for g in re.findall(r"symcat_store_(\d+)_(\d+)_(\d+)\(", text)}):
        parts.append(store_source(size, at, n))
    from .sparse_c import scatter_source, symv_source

    for n, nnz, k in sorted({tuple(map(int, g)) for g in re.findall(r"symcat_symv_(\d+)_(\d+)_(\d+)\(", text)}):
        parts.append(symv_source(n, nnz, k))
    for n, m in sorted({(int(a), int(b)) for a, b in re.findall(r"symcat_scatter_(\d+)_(\d+)\(", text)}):
        parts.append(scatter_source(n, m))
    c_path.write_text("".join(parts))
    return c_path
