/* The sphere model's yes/no collision test, compiled (ocpkit.planner.sphere_check explains it and fills Model).
 *
 * A configuration collides when some clearance is below the margin: a self-collision pair, a sphere against an
 * obstacle (sphere, box or cylinder: the exact signed distance of ocpkit.geometry.distance) or against a workspace
 * face. Units: metres and radians; rotations row-major. */

typedef struct {
    Chain chain;                               /* the joints (ocpkit/solvers/chain.c, compiled before this file) */
    int spheres;                               /* M, in link order */
    const int *sphere_joint;                   /* (M,) */
    const double *offset, *radius;             /* (M, 3), (M,): centre in its joint's frame, radius */
    int links;                                 /* L: runs of spheres on one joint */
    const int *link_joint, *link_first, *link_end;  /* (L,): joint, spheres [first, end) */
    const double *link_center, *link_reach;    /* (L, 3), (L,): bound centre in the joint's frame, its radius over
                                                  the link's spheres (distance + sphere radius) */
    int link_pairs;                            /* link pairs with self-collision pairs */
    const int *pair_link_a, *pair_link_b, *pair_first, *pair_end;  /* (link_pairs,): pairs [first, end) */
    const int *pair_a, *pair_b;                /* (P,): sphere pairs, grouped by link pair */
    int obstacles;
    const int *kind;                           /* (O,): 0 sphere, 1 box, 2 cylinder */
    const double *center, *axes, *half, *bound;  /* (O, 3), (O, 9), (O, 3), (O,): half sizes (box), [radius, 0,
                                                    0] (sphere), [radius, length / 2, 0] (cylinder); bound: the
                                                    farthest point of the obstacle from its centre */
    int workspace;                             /* 1 if lower and upper bound the spheres */
    const double *lower, *upper;               /* (3,) each */
    double margin;                             /* m */
} Model;

static double gap_squared(const double *a, const double *b) {
    const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

/* Whether two points are closer than `reach` (m); never when reach < 0. */
static int within(const double *a, const double *b, double reach) {
    return reach >= 0.0 && gap_squared(a, b) < reach * reach;
}

/* Whether a sphere centre c keeps less than `reach` (its radius + margin) from obstacle o: the signed distance,
 * outside the norm of the positive excesses beyond the faces, inside the largest (negative) one, below reach. */
static int touches(const Model *m, int o, const double *c, double reach) {
    const double *a = m->axes + 9 * o, *h = m->half + 3 * o;
    double d[3], p[3], excess[3];
    int count = 3;
    if (m->kind[o] == 0) return within(c, m->center + 3 * o, h[0] + reach);
    for (int k = 0; k < 3; ++k) d[k] = c[k] - m->center[3 * o + k];
    for (int k = 0; k < 3; ++k) p[k] = a[k] * d[0] + a[3 + k] * d[1] + a[6 + k] * d[2]; /* R^T d */
    if (m->kind[o] == 1) {
        for (int k = 0; k < 3; ++k) excess[k] = fabs(p[k]) - h[k];
    } else {
        excess[0] = sqrt(p[0] * p[0] + p[1] * p[1]) - h[0];
        excess[1] = fabs(p[2]) - h[1];
        count = 2;
    }
    double largest = excess[0], outside = 0.0;
    for (int k = 0; k < count; ++k) {
        if (excess[k] > largest) largest = excess[k];
        if (excess[k] > 0.0) outside += excess[k] * excess[k];
    }
    if (largest <= 0.0) return largest < reach;
    return reach > 0.0 && outside < reach * reach;
}

/* Whether configuration q collides; work holds (J + 1) 15 + (M + L) 3 doubles. Obstacles first, then the
 * workspace, then self-collision: a link (all its spheres) is passed over where its bound keeps clear. */
static int collides(const Model *m, const double *q, double *work) {
    const int frames = m->chain.joints + 1;
    double *rotation = work, *translation = work + 9 * frames, *axis = translation + 3 * frames;
    double *centers = axis + 3 * frames, *links = centers + 3 * m->spheres;
    kinematics(&m->chain, q, rotation, translation, axis);
    for (int s = 0; s < m->spheres; ++s) {
        const int j = m->sphere_joint[s];
        apply(rotation + 9 * j, translation + 3 * j, m->offset + 3 * s, centers + 3 * s);
    }
    for (int l = 0; l < m->links; ++l) {
        const int j = m->link_joint[l];
        apply(rotation + 9 * j, translation + 3 * j, m->link_center + 3 * l, links + 3 * l);
    }
    for (int o = 0; o < m->obstacles; ++o)
        for (int l = 0; l < m->links; ++l) {
            if (!within(links + 3 * l, m->center + 3 * o, m->bound[o] + m->link_reach[l] + m->margin)) continue;
            for (int s = m->link_first[l]; s < m->link_end[l]; ++s) {
                const double reach = m->radius[s] + m->margin;
                if (within(centers + 3 * s, m->center + 3 * o, m->bound[o] + reach) &&
                    touches(m, o, centers + 3 * s, reach))
                    return 1;
            }
        }
    if (m->workspace)
        for (int s = 0; s < m->spheres; ++s) {
            const double reach = m->radius[s] + m->margin;
            for (int k = 0; k < 3; ++k)
                if (centers[3 * s + k] - m->lower[k] < reach || m->upper[k] - centers[3 * s + k] < reach) return 1;
        }
    for (int g = 0; g < m->link_pairs; ++g) {
        const int a = m->pair_link_a[g], b = m->pair_link_b[g];
        if (!within(links + 3 * a, links + 3 * b, m->link_reach[a] + m->link_reach[b] + m->margin)) continue;
        for (int k = m->pair_first[g]; k < m->pair_end[g]; ++k) {
            const int i = m->pair_a[k], j = m->pair_b[k];
            if (within(centers + 3 * i, centers + 3 * j, m->radius[i] + m->radius[j] + m->margin)) return 1;
        }
    }
    return 0;
}

/* Per configuration of q (count, dof): hits[k] = 1 if it collides. With stop_at_first, the configurations after
 * the first colliding one are not checked (left 0). Returns the first colliding one's index, -1 if none. */
int sphere_check(const Model *m, const double *q, int count, int stop_at_first, unsigned char *hits,
                 double *work) {
    int first = -1;
    for (int k = 0; k < count; ++k) {
        hits[k] = (unsigned char)collides(m, q + (long)k * m->chain.dof, work);
        if (hits[k] && first < 0) {
            first = k;
            if (stop_at_first) break;
        }
    }
    return first;
}
