/* A robot's joint chain and its kinematics, for the hand-written C that includes it (ocpkit.solvers.chain fills
 * Chain from the model; the path search's collision test and the collision rows' derivatives read it).
 * Units: metres and radians; rotations row-major. */
#include <math.h>
#include <string.h>

typedef struct {
    int dof;                                   /* q's length */
    int joints;                                /* J: the model's joints 1..J (0 is the world) */
    const int *parent, *index, *revolute;      /* (J,): parent joint, q index, 1 if revolute else prismatic */
    const double *rotation, *cross, *cross_squared;  /* (J, 9): placement in the parent, [a]x, [a]x^2 */
    const double *translation, *slide;         /* (J, 3): placement in the parent, axis in the parent */
} Chain;

static void compose(const double *a, const double *b, double *out) { /* out = a b, 3 x 3 */
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            out[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

static void apply(const double *r, const double *t, const double *v, double *out) { /* out = r v + t */
    for (int i = 0; i < 3; ++i)
        out[i] = r[3 * i] * v[0] + r[3 * i + 1] * v[1] + r[3 * i + 2] * v[2] + t[i];
}

/* Every joint's world rotation (J + 1, 9), origin (J + 1, 3) and axis (J + 1, 3) at q: Rodrigues for a revolute
 * joint. */
static void kinematics(const Chain *m, const double *q, double *rotation, double *origin, double *axis) {
    static const double eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, none[3] = {0, 0, 0};
    memcpy(rotation, eye, sizeof eye);
    memset(origin, 0, 3 * sizeof(double));
    memset(axis, 0, 3 * sizeof(double));
    for (int j = 1; j <= m->joints; ++j) {
        const int p = m->parent[j - 1];
        const double *placed = m->rotation + 9 * (j - 1), *up = rotation + 9 * p, *slide = m->slide + 3 * (j - 1);
        double local[9], shift[3];
        const double v = q[m->index[j - 1]];
        for (int k = 0; k < 3; ++k) shift[k] = m->translation[3 * (j - 1) + k];
        if (m->revolute[j - 1]) {
            double turn[9], s = sin(v), c = 1.0 - cos(v);
            for (int k = 0; k < 9; ++k)
                turn[k] = eye[k] + s * m->cross[9 * (j - 1) + k] + c * m->cross_squared[9 * (j - 1) + k];
            compose(placed, turn, local);
        } else {
            memcpy(local, placed, sizeof local);
            for (int k = 0; k < 3; ++k) shift[k] += v * slide[k];
        }
        compose(up, local, rotation + 9 * j);
        apply(up, origin + 3 * p, shift, origin + 3 * j);
        apply(up, none, slide, axis + 3 * j);
    }
}
