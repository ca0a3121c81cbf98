"""Small dense solves for the model's hot loop (numba): 4x4 systems, no allocation per call."""
from model.jit import kernel


@kernel
def solve_in_place(a, b, n: int, m: int) -> bool:
    """Solve A X = B for the leading n x n block of `a` and n x m block of `b`.

    Gaussian elimination with partial pivoting. `a` is destroyed and `b` holds X on return.
    Returns False when A is singular to working precision.
    """
    for col in range(n):
        pivot = col
        best = abs(a[col, col])
        for row in range(col + 1, n):
            if abs(a[row, col]) > best:
                best = abs(a[row, col])
                pivot = row
        if best < 1e-300:
            return False
        if pivot != col:
            for j in range(n):
                a[col, j], a[pivot, j] = a[pivot, j], a[col, j]
            for j in range(m):
                b[col, j], b[pivot, j] = b[pivot, j], b[col, j]
        inv = 1.0 / a[col, col]
        for row in range(col + 1, n):
            factor = a[row, col] * inv
            if factor != 0.0:
                for j in range(col, n):
                    a[row, j] -= factor * a[col, j]
                for j in range(m):
                    b[row, j] -= factor * b[col, j]
    _back_substitute(a, b, n, m)
    return True


@kernel
def _back_substitute(a, b, n: int, m: int) -> None:
    """X from the upper triangle of A (after elimination): b holds X on return."""
    for col in range(n - 1, -1, -1):
        inv = 1.0 / a[col, col]
        for j in range(m):
            acc = b[col, j]
            for k in range(col + 1, n):
                acc -= a[col, k] * b[k, j]
            b[col, j] = acc * inv
