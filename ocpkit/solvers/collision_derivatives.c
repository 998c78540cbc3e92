/* The collision rows' first and second derivatives in q, compiled (ocpkit.solvers.collision_derivatives
 * explains them and fills Model and Scene).
 *
 * A row is a group of terms (one term, or their soft minimum), or a workspace row. A term is a squared clearance
 * of one sphere centre c (to an obstacle sphere, box or cylinder) or of two (a self-collision pair: d = c_a - c_b)
 * less (radii + margin)^2. Its gradient g and Hessian H in c (in d for a pair) are closed forms; the chain rule
 * through the kinematics gives the rest:
 *   grad_q t = J^T g,   hess_q t = J^T H J + sum_k g_k hess_q c_k,
 * J the centre's (or d's) Jacobian, whose column of a revolute joint is a x (c - o) (axis a, origin o, world
 * frame), of a prismatic joint a; and hess_q c's entry for joints j1, j2 (j1 an ancestor of j2 or j2 itself)
 * a_j1 x (column j2) if j1 is revolute, else 0. A soft minimum r = -log(sum exp(-beta t_i)) / beta has weights
 * sigma_i = dr/dt_i (summing to 1) and hess_q r = sum sigma_i hess_q t_i + beta (gg^T - sum sigma_i g_i g_i^T),
 * g = sum sigma_i g_i, g_i = grad_q t_i. Units: metres and radians; rotations row-major. */

typedef struct {
    Chain chain;                               /* the joints (chain.c, compiled before this file) */
    int spheres;
    const int *sphere_joint;                   /* (M,) */
    const double *offset, *radius;             /* (M, 3), (M,): centre in its joint's frame, radius */
    int used;
    const int *used_spheres;                   /* (U,): the spheres some row reads (the others are not computed) */
    int terms;                                 /* T, in the rows' evaluation order (their margin caps' order) */
    const int *kind, *first, *second;          /* (T,): 0 pair (spheres first, second), 1 sphere first against
                                                  obstacle sphere second, 2 box second, 3 cylinder second */
    int groups;                                /* rows of terms */
    const int *group_start, *group_terms;      /* (groups + 1,), (T,): group g's terms group_terms[start[g]..] */
    int faces;                                 /* workspace rows, after the groups */
    const int *face_sphere, *face_axis, *face_sides;  /* (F,): sides 1 the lower face, 2 the upper, 3 both */
    double sharpness;                          /* beta of the soft minimum, 1/m^2 */
    double radial_eps;                         /* m^2 under a cylinder's radial root */
} Model;

typedef struct {                               /* the NLP parameters' values */
    double margin;                             /* m */
    const double *cap;                         /* (T + F,): each term's and face row's largest margin, m */
    const double *sphere_center, *sphere_radius;                     /* (S, 3), (S,) */
    const double *box_center, *box_half, *box_rotation;              /* (B, 3), (B, 3), (B, 9) */
    const double *cylinder_center, *cylinder_half, *cylinder_rotation;  /* (C, 3), (C, 2) [radius, half length],
                                                                         (C, 9) */
    const double *workspace;                   /* (6,): lower, upper */
} Scene;

static void cross(const double *a, const double *b, double *out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

/* Sphere s's centre (3,) and Jacobian (3, dof), column-major, zero where a joint does not move it. */
static void sphere_jacobian(const Model *m, int s, const double *rotation, const double *origin,
                            const double *axis, double *center, double *jacobian) {
    int j = m->sphere_joint[s];
    apply(rotation + 9 * j, origin + 3 * j, m->offset + 3 * s, center);
    memset(jacobian, 0, 3 * m->chain.dof * sizeof(double));
    for (; j > 0; j = m->chain.parent[j - 1]) {
        double *column = jacobian + 3 * m->chain.index[j - 1];
        if (m->chain.revolute[j - 1]) {
            double arm[3] = {center[0] - origin[3 * j], center[1] - origin[3 * j + 1], center[2] - origin[3 * j + 2]};
            cross(axis + 3 * j, arm, column);
        } else {
            memcpy(column, axis + 3 * j, 3 * sizeof(double));
        }
    }
}

/* w^T hess_q c_s added to hess (dof, dof) for sphere s with Jacobian `jacobian` (3, dof) (file comment). */
static void add_curvature(const Model *m, int s, const double *axis, const double *jacobian, const double *w,
                          double *hess) {
    const int n = m->chain.dof;
    for (int j1 = m->sphere_joint[s]; j1 > 0; j1 = m->chain.parent[j1 - 1]) {
        if (!m->chain.revolute[j1 - 1]) continue;
        double u[3];
        cross(w, axis + 3 * j1, u);  /* w . (a x v) = v . (w x a) */
        const int k1 = m->chain.index[j1 - 1];
        for (int j2 = m->sphere_joint[s];; j2 = m->chain.parent[j2 - 1]) {
            const int k2 = m->chain.index[j2 - 1];
            const double *v = jacobian + 3 * k2;
            const double value = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            hess[k1 * n + k2] += value;
            if (k1 != k2) hess[k2 * n + k1] += value;
            if (j2 == j1) break;
        }
    }
}

/* Term i's value (m^2) at the centres; with g and h, its gradient (3,) and Hessian (3, 3) in its point (c, or d
 * for a pair). */
static double term(const Model *m, const Scene *sc, int i, const double *centers, double *g, double *h) {
    const int a = m->first[i], o = m->second[i];
    const double margin = fmin(sc->margin, sc->cap[i]);
    const double *c = centers + 3 * a;
    if (m->kind[i] <= 1) {
        const double *other = m->kind[i] == 0 ? centers + 3 * o : sc->sphere_center + 3 * o;
        const double reach = m->radius[a] + margin + (m->kind[i] == 0 ? m->radius[o] : sc->sphere_radius[o]);
        double d[3], value = 0.0;
        for (int k = 0; k < 3; ++k) {
            d[k] = c[k] - other[k];
            value += d[k] * d[k];
        }
        if (g) {
            for (int k = 0; k < 3; ++k) g[k] = 2.0 * d[k];
            for (int k = 0; k < 9; ++k) h[k] = (k % 4 == 0) ? 2.0 : 0.0;
        }
        return value - reach * reach;
    }
    const int box = m->kind[i] == 2;
    const double *center = (box ? sc->box_center : sc->cylinder_center) + 3 * o;
    const double *r = (box ? sc->box_rotation : sc->cylinder_rotation) + 9 * o;
    const double *half = box ? sc->box_half + 3 * o : sc->cylinder_half + 2 * o;
    double d[3], p[3], gp[3] = {0, 0, 0}, hp[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, value = 0.0;
    for (int k = 0; k < 3; ++k) d[k] = c[k] - center[k];
    for (int k = 0; k < 3; ++k) p[k] = r[k] * d[0] + r[3 + k] * d[1] + r[6 + k] * d[2]; /* R^T d */
    if (box) {
        for (int k = 0; k < 3; ++k) {
            const double excess = fabs(p[k]) - half[k];
            if (excess > 0.0) {
                value += excess * excess;
                gp[k] = 2.0 * excess * sign(p[k]);
                hp[4 * k] = 2.0;
            }
        }
    } else {
        const double rho = sqrt(p[0] * p[0] + p[1] * p[1] + m->radial_eps), radial = rho - half[0];
        const double axial = fabs(p[2]) - half[1];
        if (radial > 0.0) {
            const double x = p[0] / rho, y = p[1] / rho;
            value += radial * radial;
            gp[0] = 2.0 * radial * x;
            gp[1] = 2.0 * radial * y;
            hp[0] = 2.0 * (x * x + radial * (1.0 - x * x) / rho);
            hp[4] = 2.0 * (y * y + radial * (1.0 - y * y) / rho);
            hp[1] = hp[3] = 2.0 * x * y * (1.0 - radial / rho);
        }
        if (axial > 0.0) {
            value += axial * axial;
            gp[2] = 2.0 * axial * sign(p[2]);
            hp[8] = 2.0;
        }
    }
    if (g) {  /* back to the world frame: g = R gp, h = R hp R^T */
        double rh[9];
        for (int k = 0; k < 3; ++k) g[k] = r[3 * k] * gp[0] + r[3 * k + 1] * gp[1] + r[3 * k + 2] * gp[2];
        compose(r, hp, rh);
        for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y)
                h[3 * x + y] = rh[3 * x] * r[3 * y] + rh[3 * x + 1] * r[3 * y + 1] + rh[3 * x + 2] * r[3 * y + 2];
    }
    const double reach = m->radius[a] + margin;
    return value - reach * reach;
}

/* The derivatives at `count` points q (count, dof): jac (count, rows, dof), each point's rows x dof column-major;
 * with lam (count, rows) also hess (count, dof, dof): the Hessian of lam^T rows. Either output may be NULL. work
 * holds 15 (J + 1) + M (6 + 3 dof) + T + 8 dof doubles. */
void collision_derivatives(const Model *m, const Scene *sc, const double *q, int count, const double *lam,
                           double *jac, double *hess, double *work) {
    const int n = m->chain.dof, rows = m->groups + m->faces, frames = m->chain.joints + 1;
    double *rotation = work, *origin = rotation + 9 * frames, *axis = origin + 3 * frames;
    double *centers = axis + 3 * frames, *jacobians = centers + 3 * m->spheres;
    double *weights = jacobians + 3 * n * m->spheres, *values = weights + 3 * m->spheres;
    double *joined = values + m->terms, *gradient = joined + 3 * n, *sum = gradient + n, *scaled = sum + n;
    for (int point = 0; point < count; ++point) {
        double *jac_point = jac ? jac + (long)point * rows * n : 0;
        double *hess_point = hess ? hess + (long)point * n * n : 0;
        const double *lam_point = lam ? lam + (long)point * rows : 0;
        kinematics(&m->chain, q + (long)point * n, rotation, origin, axis);
        for (int k = 0; k < m->used; ++k) {
            const int s = m->used_spheres[k];
            sphere_jacobian(m, s, rotation, origin, axis, centers + 3 * s, jacobians + 3 * n * s);
        }
        if (hess_point) {
            memset(hess_point, 0, n * n * sizeof(double));
            memset(weights, 0, 3 * m->spheres * sizeof(double));
        }
        for (int r = 0; r < m->groups; ++r) {
            const int start = m->group_start[r], end = m->group_start[r + 1], soft = end - start > 1;
            const double weight = lam_point ? lam_point[r] : 0.0;
            double low = INFINITY, total = 0.0;
            if (soft) {
                for (int k = start; k < end; ++k) {
                    values[k] = term(m, sc, m->group_terms[k], centers, 0, 0);
                    if (values[k] < low) low = values[k];
                }
                for (int k = start; k < end; ++k) total += exp(-m->sharpness * (values[k] - low));
            }
            memset(sum, 0, n * sizeof(double));
            for (int k = start; k < end; ++k) {
                const int i = m->group_terms[k], a = m->first[i], b = m->second[i];
                const double sigma = soft ? exp(-m->sharpness * (values[k] - low)) / total : 1.0;
                double g[3], h[9];
                term(m, sc, i, centers, g, h);
                const double *ja = jacobians + 3 * n * a;
                for (int x = 0; x < 3 * n; ++x)
                    joined[x] = m->kind[i] == 0 ? ja[x] - jacobians[3 * n * b + x] : ja[x];
                for (int c = 0; c < n; ++c) {
                    const double *column = joined + 3 * c;
                    gradient[c] = g[0] * column[0] + g[1] * column[1] + g[2] * column[2];
                    sum[c] += sigma * gradient[c];
                }
                if (!hess_point || weight == 0.0) continue;
                const double w = weight * sigma;
                for (int c = 0; c < n; ++c)  /* scaled = h J, (3, dof) */
                    for (int x = 0; x < 3; ++x)
                        scaled[3 * c + x] = h[3 * x] * joined[3 * c] + h[3 * x + 1] * joined[3 * c + 1] +
                                            h[3 * x + 2] * joined[3 * c + 2];
                for (int c = 0; c < n; ++c)
                    for (int e = 0; e < n; ++e) {
                        const double *left = joined + 3 * e, *right = scaled + 3 * c;
                        hess_point[c * n + e] += w * (left[0] * right[0] + left[1] * right[1] + left[2] * right[2]);
                        if (soft) hess_point[c * n + e] -= w * m->sharpness * gradient[c] * gradient[e];
                    }
                for (int x = 0; x < 3; ++x) {
                    weights[3 * a + x] += w * g[x];
                    if (m->kind[i] == 0) weights[3 * b + x] -= w * g[x];
                }
            }
            if (jac_point)
                for (int c = 0; c < n; ++c) jac_point[c * rows + r] = sum[c];
            if (hess_point && soft && weight != 0.0)
                for (int c = 0; c < n; ++c)
                    for (int e = 0; e < n; ++e) hess_point[c * n + e] += weight * m->sharpness * sum[c] * sum[e];
        }
        for (int f = 0; f < m->faces; ++f) {
            const int s = m->face_sphere[f], x = m->face_axis[f], r = m->groups + f;
            double slope = m->face_sides[f] == 2 ? -1.0 : 1.0;
            if (m->face_sides[f] == 3) {
                const double inset = m->radius[s] + fmin(sc->margin, sc->cap[m->terms + f]);
                slope = 1.0 / ((sc->workspace[x + 3] - inset) - (sc->workspace[x] + inset));
            }
            if (jac_point)
                for (int c = 0; c < n; ++c) jac_point[c * rows + r] = slope * jacobians[3 * n * s + 3 * c + x];
            if (hess_point) weights[3 * s + x] += lam_point[r] * slope;
        }
        if (!hess_point) continue;
        for (int k = 0; k < m->used; ++k) {
            const int s = m->used_spheres[k];
            const double *w = weights + 3 * s;
            if (w[0] != 0.0 || w[1] != 0.0 || w[2] != 0.0)
                add_curvature(m, s, axis, jacobians + 3 * n * s, w, hess_point);
        }
    }
}
