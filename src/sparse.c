/* Sparse symmetric systems: a square matrix in compressed rows (each row's columns ascending,
 * duplicates summed) assembled from (row, column, value) triplets by two stable counting sorts
 * (by column, then by row, so that duplicates meet in input order and the result does not depend
 * on anything but the input), the product with a vector, and a Jacobi-preconditioned conjugate
 * gradient solver for symmetric positive definite matrices (Hestenes-Stiefel with the diagonal as
 * preconditioner; when the recurrence says the tolerance is met the true residual b - A x is
 * recomputed, and the iteration restarts from it if the recurrence had drifted). Used by the
 * rolling-ball operator's conformal map (seed 002) and whatever else needs a Laplacian solve. All
 * in double; a built matrix is read-only and may be used by many threads at once. */

sfb_result sfb__sparse_from_triplets(sfb_context *ctx, int n, int count, const int *row, const int *col, const double *val,
                                     sfb__sparse *out) {
    int *cnt = NULL, *ord1 = NULL, *ord2 = NULL, k, i, nnz = 0;
    size_t bytes_i, bytes_d;
    sfb__sparse m;
    if (!out) return ctx ? sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sfb__sparse_from_triplets: NULL matrix") : SFB_INVALID_ARGS;
    memset(out, 0, sizeof *out);
    if (!ctx) return SFB_INVALID_ARGS;
    if (n < 0 || count < 0 || (count > 0 && (!row || !col || !val)))
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sparse matrix: %d rows and %d triplets without their arrays", n,
                          count);
    for (k = 0; k < count; ++k)
        if (row[k] < 0 || row[k] >= n || col[k] < 0 || col[k] >= n)
            return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "sparse matrix: triplet %d (%d, %d) outside the %d x %d matrix", k,
                              row[k], col[k], n, n);
    memset(&m, 0, sizeof m);
    m.n = n;
    if (!sfb__mul_size((size_t)count, sizeof(int), &bytes_i) ||
        !(cnt = (int *)sfb__calloc(ctx, (size_t)n + 1, sizeof(int))) || !(ord1 = (int *)sfb__alloc(ctx, bytes_i)) ||
        !(ord2 = (int *)sfb__alloc(ctx, bytes_i)) || !(m.row_off = (int *)sfb__calloc(ctx, (size_t)n + 1, sizeof(int)))) {
        sfb__free(ctx, cnt);
        sfb__free(ctx, ord1);
        sfb__free(ctx, ord2);
        return sfb__oom(ctx, "a sparse matrix");
    }
    /* stable counting sort by column, then by row: rows in order, columns ascending in each,
     * equal (row, column) in input order */
    for (k = 0; k < count; ++k) cnt[col[k] + 1]++;
    for (i = 0; i < n; ++i) cnt[i + 1] += cnt[i];
    for (k = 0; k < count; ++k) ord1[cnt[col[k]]++] = k;
    memset(cnt, 0, ((size_t)n + 1) * sizeof(int));
    for (k = 0; k < count; ++k) cnt[row[k] + 1]++;
    for (i = 0; i < n; ++i) cnt[i + 1] += cnt[i];
    for (k = 0; k < count; ++k) {
        const int t = ord1[k];
        ord2[cnt[row[t]]++] = t;
    }
    /* distinct entries per row */
    for (k = 0; k < count; ++k) {
        const int t = ord2[k];
        if (k == 0 || row[t] != row[ord2[k - 1]] || col[t] != col[ord2[k - 1]]) {
            m.row_off[row[t] + 1]++;
            nnz++;
        }
    }
    for (i = 0; i < n; ++i) m.row_off[i + 1] += m.row_off[i];
    if (!sfb__mul_size((size_t)nnz, sizeof(double), &bytes_d) || !(m.col = (int *)sfb__alloc(ctx, (size_t)nnz * sizeof(int))) ||
        !(m.val = (double *)sfb__alloc(ctx, bytes_d))) {
        sfb__free(ctx, cnt);
        sfb__free(ctx, ord1);
        sfb__free(ctx, ord2);
        sfb__sparse_free(ctx, &m);
        return sfb__oom(ctx, "a sparse matrix");
    }
    nnz = 0;
    for (k = 0; k < count; ++k) {
        const int t = ord2[k];
        if (k == 0 || row[t] != row[ord2[k - 1]] || col[t] != col[ord2[k - 1]]) {
            m.col[nnz] = col[t];
            m.val[nnz] = val[t];
            nnz++;
        } else
            m.val[nnz - 1] += val[t];
    }
    sfb__free(ctx, cnt);
    sfb__free(ctx, ord1);
    sfb__free(ctx, ord2);
    *out = m;
    return SFB_SUCCESS;
}

void sfb__sparse_free(sfb_context *ctx, sfb__sparse *m) {
    if (!m) return;
    if (ctx) {
        sfb__free(ctx, m->row_off);
        sfb__free(ctx, m->col);
        sfb__free(ctx, m->val);
    }
    memset(m, 0, sizeof *m);
}

void sfb__sparse_mul(const sfb__sparse *A, const double *x, double *y) {
    int i, k;
    for (i = 0; i < A->n; ++i) {
        double s = 0.0;
        for (k = A->row_off[i]; k < A->row_off[i + 1]; ++k) s += A->val[k] * x[A->col[k]];
        y[i] = s;
    }
}

static double sparse_dot(int n, const double *a, const double *b) {
    double s = 0.0;
    int i;
    for (i = 0; i < n; ++i) s += a[i] * b[i];
    return s;
}

sfb_result sfb__sparse_cg(sfb_context *ctx, const sfb__sparse *A, const double *b, double *x, double tol, int max_iter, int *iters,
                          double *residual) {
    double *dinv = NULL, *r, *z, *p, *q, bnorm, rz, rnorm, rel = 0.0;
    int n, i, k, it = 0, fresh = 1;
    size_t bytes;
    sfb_result res = SFB_SUCCESS;
    if (iters) *iters = 0;
    if (residual) *residual = 0.0;
    if (!ctx) return SFB_INVALID_ARGS;
    if (!A || !b || !x || A->n < 0 || (A->n > 0 && (!A->row_off || !A->col || !A->val)) || !(tol >= 0.0) || max_iter < 0)
        return sfb__error(ctx, SFB_INVALID_ARGS, SFB_ELEMENT_NONE, -1, "conjugate gradients: bad arguments");
    n = A->n;
    if (n == 0) return SFB_SUCCESS;
    for (i = 0; i < n; ++i)
        if (!(b[i] - b[i] == 0.0) || !(x[i] - x[i] == 0.0))
            return sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "conjugate gradients: non-finite %s at row %d",
                              b[i] - b[i] == 0.0 ? "start value" : "right-hand side", i);
    if (!sfb__mul_size((size_t)n, 5 * sizeof(double), &bytes) || !(dinv = (double *)sfb__alloc(ctx, bytes)))
        return sfb__oom(ctx, "conjugate gradients");
    r = dinv + n;
    z = r + n;
    p = z + n;
    q = p + n;
    for (i = 0; i < n; ++i) {
        double d = 0.0;
        for (k = A->row_off[i]; k < A->row_off[i + 1]; ++k)
            if (A->col[k] == i) d = A->val[k];
        if (!(d > 0.0) || !(d - d == 0.0)) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                             "conjugate gradients: diagonal entry %d is %g, not positive (the matrix is not positive definite)", i, d);
            goto done;
        }
        dinv[i] = 1.0 / d;
    }
    bnorm = sqrt(sparse_dot(n, b, b));
    if (bnorm == 0.0) {
        /* b = 0: x = 0 exactly */
        memset(x, 0, (size_t)n * sizeof(double));
        goto done;
    }
    rz = 0.0;
    for (;;) {
        if (fresh) {
            /* r = b - A x, from x itself (the start, or a restart after the recurrence drifted) */
            sfb__sparse_mul(A, x, r);
            for (i = 0; i < n; ++i) {
                r[i] = b[i] - r[i];
                z[i] = dinv[i] * r[i];
                p[i] = z[i];
            }
            rz = sparse_dot(n, r, z);
        }
        rnorm = sqrt(sparse_dot(n, r, r));
        rel = rnorm / bnorm;
        if (!(rel - rel == 0.0)) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1, "conjugate gradients: a non-finite value after %d iterations", it);
            goto done;
        }
        if (rel <= tol) {
            if (fresh) break;
            fresh = 1; /* confirm with the true residual */
            continue;
        }
        if (it >= max_iter) {
            res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                             "conjugate gradients did not converge in %d iterations (residual %g of |b|, tolerance %g)", it, rel, tol);
            goto done;
        }
        fresh = 0;
        {
            double pq, alpha, beta, rz_new;
            sfb__sparse_mul(A, p, q);
            pq = sparse_dot(n, p, q);
            if (!(pq > 0.0)) {
                res = sfb__error(ctx, SFB_INVALID_VALUE, SFB_ELEMENT_NONE, -1,
                                 "conjugate gradients: p.Ap = %g after %d iterations (the matrix is not positive definite)", pq, it);
                goto done;
            }
            alpha = rz / pq;
            for (i = 0; i < n; ++i) {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
                z[i] = dinv[i] * r[i];
            }
            rz_new = sparse_dot(n, r, z);
            beta = rz_new / rz;
            for (i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
            rz = rz_new;
            it++;
        }
    }
done:
    if (iters) *iters = it;
    if (residual) *residual = rel;
    sfb__free(ctx, dinv);
    return res;
}
