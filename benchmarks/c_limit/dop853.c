/*
 * The C limit of rollingtop's integrator (issue 13): the same DOP853 integration of the meridian
 * model (geometric nu, kernel code 0) written in plain C99, as a hand-written reference for
 * rollingtop's compiled (numba) stepper.
 *
 * Everything mirrors rollingtop, operation by operation and rounding by rounding (see FMA below),
 * so that the run takes the same accepted and rejected steps and, on a CPU with FMA, ends in the
 * same state to the last bit:
 *
 *   - tableau, stages, error estimates: src/rollingtop/_compiled/_dop853_tableau.py and the
 *     generated _dop853_stages.py (stage, scaled_errors), coefficients printed to full precision;
 *   - step-size controller, initial step, FSAL, final step cut to hit t_end exactly, status codes:
 *     _compiled/_dop853.py and _compiled/_template/stepper.py (initial_step, start, run_rows);
 *   - dense output at the sample times (stages 14-16, 7th-order interpolant), each sample
 *     projected; the first loss of contact located by bisection on it: _dop853_dense.py;
 *   - closed-form right-hand side: contact/meridian.py (nu_geometric, accel) ->
 *     contact/_closed.py (rhs_contact) with the helpers of contact/_rows.py, kinematics of
 *     _compiled/_template/dynamics.py (_kinematics, with _compiled/_kernel.py frame_rates);
 *   - projection after every accepted step: _compiled/_template/dynamics.py (project:
 *     Newton-Schulz steps of the frame, then meridian sync_direction, then the closed-form
 *     project_velocity);
 *   - reaction monitoring after every accepted step: _kernel.reaction and _dop853.update_track.
 *
 * Events are omitted. The state has the layout of src/rollingtop/_layout.py:
 * y = (v[3], w[3], alpha[3], beta[3], gamma[3], X, Y, psi_nu); parameters p = (R, m, g, a3, I1,
 * I2, I3).
 *
 * Entry point (see its comment below): rt_integrate; the rt_* functions at the end expose the
 * pieces for checks. No dependencies beyond libm. Built by benchmarks/c_limit.py with the system
 * compiler: -O3 -march=native -ffp-contract=off.
 */

#include <math.h>

#define N 18
/* math.pi (M_PI is not C99) */
#define PI 3.141592653589793

/* FMA(a, b, c) = a b + c. numba compiles rollingtop's kernels for the host CPU with fused
 * multiply-add allowed (fastmath={"contract"}), and LLVM then fuses a product into the sum or
 * difference that uses it: the left operand when both are products used once, else the one that
 * is. The fusions are spelled out here (compiled with -ffp-contract=off, so the C compiler adds
 * none of its own) so that the C code rounds exactly as rollingtop's does. Without hardware FMA
 * (FP_FAST_FMA undefined: no -march=native, or a CPU without it) numba fuses nothing either. */
#ifdef FP_FAST_FMA
#define FMA(a, b, c) fma((a), (b), (c))
#else
#define FMA(a, b, c) ((a) * (b) + (c))
#endif

/* status codes of _compiled/_dop853.py */
#define FINISHED 0
#define STEP_TOO_SMALL (-1)
#define NOT_FINITE (-2)
#define TOO_MANY_REJECTED (-3)
#define MAX_REJECTED_IN_A_ROW 100

#define SAFETY 0.9
#define MIN_FACTOR 0.2
#define MAX_FACTOR 10.0
#define ERROR_EXPONENT (-1.0 / 8.0)

/* indices into the reaction-tracking array (as in _dop853.py) */
enum { MIN_NORMAL, T_MIN_NORMAL, T_CONTACT_LOST, MAX_RATIO, T_MAX_RATIO, LAST_NORMAL };

/* What reaction() needs from the last right-hand side: the multipliers and force directions
 * (rollingtop's ws[4] and ws[2]). */
typedef struct {
    double l1, l2;
    double d0[3], d1[3];
} Reaction;

/* ---------------------------------------------------------------- right-hand side ---------- */

/* contact/_rows.py row_bias: J' u = (d', v) + (r' x d + r x d', w) */
static inline double row_bias(const double *y, double r1, double r2, double r3, double rd1,
                              double rd2, double rd3, double d1, double d2, double d3, double dd1,
                              double dd2, double dd3)
{
    double q1 = FMA(-r3, dd2, FMA(r2, dd3, FMA(rd2, d3, -(rd3 * d2))));
    double q2 = FMA(-r1, dd3, FMA(r3, dd1, FMA(rd3, d1, -(rd1 * d3))));
    double q3 = FMA(-r2, dd1, FMA(r1, dd2, FMA(rd1, d2, -(rd2 * d1))));
    double b = FMA(dd1, y[0], dd2 * y[1]);
    b = FMA(dd3, y[2], b);
    b = FMA(q1, y[3], b);
    b = FMA(q2, y[4], b);
    return FMA(q3, y[5], b);
}

/* contact/meridian.py nu_geometric: nu = (e3 - gamma3 gamma)/s and its rate */
static inline void nu_geometric(const double *y, double *n1, double *n2, double *n3, double *nd1,
                                double *nd2, double *nd3)
{
    double w1 = y[3], w2 = y[4], w3 = y[5];
    double g1 = y[12], g2 = y[13], g3 = y[14];
    double gd1 = FMA(g2, w3, -(g3 * w2));
    double gd2 = FMA(g3, w1, -(g1 * w3));
    double gd3 = FMA(g1, w2, -(g2 * w1));
    double s = sqrt(FMA(g1, g1, g2 * g2));
    double sd = FMA(g1, gd1, g2 * gd2) / s;
    double a = -g3 * g1 / s;
    double b = -g3 * g2 / s;
    *n1 = a;
    *n2 = b;
    *n3 = s;
    *nd1 = -FMA(gd3, g1, g3 * gd1) / s - a * sd / s;
    *nd2 = -FMA(gd3, g2, g3 * gd2) / s - b * sd / s;
    *nd3 = sd;
}

/* (d1, d2, d3) im + x1 x1 i1 + x2 x2 i2 + x3 x3 i3 for the entries of J M^-1 J^T, with the dot
 * product dd = (d, e) of the two rows' directions given */
#define MASS_ENTRY(dd, x1, y1, x2, y2, x3, y3)                                                   \
    FMA((x3) * (y3), i3, FMA((x2) * (y2), i2, FMA((dd), im, (x1) * (y1) * i1)))

/* _compiled/_template/dynamics.py rhs for code 0: meridian accel (contact/_closed.py
 * rhs_contact with the row along the geometric nu) and _kinematics. Returns the number of
 * rows, 2. */
static int rhs(const double *p, const double *y, double *dy, Reaction *ws)
{
    double n1, n2, n3, nd1, nd2, nd3;
    nu_geometric(y, &n1, &n2, &n3, &nd1, &nd2, &nd3);

    double w1 = y[3], w2 = y[4], w3 = y[5];
    double g1 = y[12], g2 = y[13], g3 = y[14];
    double gd1 = FMA(g2, w3, -(g3 * w2));
    double gd2 = FMA(g3, w1, -(g1 * w3));
    double gd3 = FMA(g1, w2, -(g2 * w1));
    /* contact_arm_rate */
    double R = p[0], a3 = p[3];
    double r1 = -R * g1, r2 = -R * g2, r3 = FMA(-R, g3, -a3);
    double rd1 = -R * gd1, rd2 = -R * gd2, rd3 = -R * gd3;
    double im = 1.0 / p[1], i1 = 1.0 / p[4], i2 = 1.0 / p[5], i3 = 1.0 / p[6];
    /* free_forces */
    double m = p[1], g = p[2], I1 = p[4], I2 = p[5], I3 = p[6];
    double v1 = y[0], v2 = y[1], v3 = y[2];
    double f1 = FMA(m, FMA(v2, w3, -(v3 * w2)), -(m * g * y[12]));
    double f2 = FMA(m, FMA(v3, w1, -(v1 * w3)), -(m * g * y[13]));
    double f3 = FMA(m, FMA(v1, w2, -(v2 * w1)), -(m * g * y[14]));
    double f4 = (I2 - I3) * w2 * w3;
    double f5 = (I3 - I1) * w3 * w1;
    double f6 = (I1 - I2) * w1 * w2;
    /* row 1: d = gamma */
    double a1 = FMA(r2, g3, -(r3 * g2)), a2 = FMA(r3, g1, -(r1 * g3)),
           a3_ = FMA(r1, g2, -(r2 * g1));
    double bias1 = row_bias(y, r1, r2, r3, rd1, rd2, rd3, g1, g2, g3, gd1, gd2, gd3);
    double gg = FMA(g3, g3, FMA(g1, g1, g2 * g2));
    double A11 = MASS_ENTRY(gg, a1, a1, a2, a2, a3_, a3_);
    double c1 = FMA(-FMA(g3, f3, FMA(g1, f1, g2 * f2)), im, -bias1)
                - FMA(a3_ * f6, i3, FMA(a1 * f4, i1, a2 * f5 * i2));
    /* row 2: d = nu */
    double b1 = FMA(r2, n3, -(r3 * n2)), b2 = FMA(r3, n1, -(r1 * n3)),
           b3 = FMA(r1, n2, -(r2 * n1));
    double bias2 = row_bias(y, r1, r2, r3, rd1, rd2, rd3, n1, n2, n3, nd1, nd2, nd3);
    double gn = FMA(g3, n3, FMA(g1, n1, g2 * n2));
    double A12 = MASS_ENTRY(gn, a1, b1, a2, b2, a3_, b3);
    double nn = FMA(n3, n3, FMA(n1, n1, n2 * n2));
    double A22 = MASS_ENTRY(nn, b1, b1, b2, b2, b3, b3);
    double c2 = FMA(-FMA(n3, f3, FMA(n1, f1, n2 * f2)), im, -bias2)
                - FMA(b3 * f6, i3, FMA(b1 * f4, i1, b2 * f5 * i2));
    double det = FMA(A11, A22, -(A12 * A12));
    double l1 = FMA(c1, A22, -(c2 * A12)) / det;
    double l2 = FMA(A11, c2, -(A12 * c1)) / det;
    dy[0] = FMA(l2, n1, FMA(l1, g1, f1)) * im;
    dy[1] = FMA(l2, n2, FMA(l1, g2, f2)) * im;
    dy[2] = FMA(l2, n3, FMA(l1, g3, f3)) * im;
    dy[3] = FMA(l2, b1, FMA(l1, a1, f4)) * i1;
    dy[4] = FMA(l2, b2, FMA(l1, a2, f5)) * i2;
    dy[5] = FMA(l2, b3, FMA(l1, a3_, f6)) * i3;
    ws->d0[0] = g1;
    ws->d0[1] = g2;
    ws->d0[2] = g3;
    ws->d1[0] = n1;
    ws->d1[1] = n2;
    ws->d1[2] = n3;
    ws->l1 = l1;
    ws->l2 = l2;
    /* _kinematics (_kernel.frame_rates, then the model's slot 17) */
    for (int base = 6; base <= 12; base += 3) {
        double e1 = y[base], e2 = y[base + 1], e3 = y[base + 2];
        dy[base] = FMA(e2, w3, -(e3 * w2));
        dy[base + 1] = FMA(e3, w1, -(e1 * w3));
        dy[base + 2] = FMA(e1, w2, -(e2 * w1));
    }
    dy[15] = FMA(y[2], y[8], FMA(y[0], y[6], y[1] * y[7]));
    dy[16] = FMA(y[2], y[11], FMA(y[0], y[9], y[1] * y[10]));
    dy[17] = 0.0; /* meridian direction_rate, geometric variant */
    return 2;
}

/* _compiled/_kernel.py reaction: normal force N = (F, gamma) and |F - N gamma| */
static void reaction(const double *y, const Reaction *ws, double *N_out, double *T_out)
{
    double F1 = FMA(ws->l2, ws->d1[0], FMA(ws->l1, ws->d0[0], 0.0));
    double F2 = FMA(ws->l2, ws->d1[1], FMA(ws->l1, ws->d0[1], 0.0));
    double F3 = FMA(ws->l2, ws->d1[2], FMA(ws->l1, ws->d0[2], 0.0));
    double g1 = y[12], g2 = y[13], g3 = y[14];
    double N_ = FMA(F3, g3, FMA(F1, g1, F2 * g2));
    double t1 = FMA(-N_, g1, F1), t2 = FMA(-N_, g2, F2), t3 = FMA(-N_, g3, F3);
    *N_out = N_;
    *T_out = sqrt(FMA(t3, t3, FMA(t1, t1, t2 * t2)));
}

/* _compiled/_template/dynamics.py project (code 0): Newton-Schulz steps of the frame, psi_nu
 * synchronised with the axis azimuth (contact/_rows.py sync_direction), closed-form velocity
 * projection (contact/_closed.py project_contact with the geometric nu). */
static void project(const double *p, double *y)
{
    /* FRAME_ITERATIONS steps at most, until a step starts within FRAME_ONE_STEP */
    for (int it = 0; it < 6; it++) {
        double G00 = FMA(y[8], y[8], FMA(y[6], y[6], y[7] * y[7]));
        double G11 = FMA(y[11], y[11], FMA(y[9], y[9], y[10] * y[10]));
        double G22 = FMA(y[14], y[14], FMA(y[12], y[12], y[13] * y[13]));
        double G01 = FMA(y[8], y[11], FMA(y[6], y[9], y[7] * y[10]));
        double G02 = FMA(y[8], y[14], FMA(y[6], y[12], y[7] * y[13]));
        double G12 = FMA(y[11], y[14], FMA(y[9], y[12], y[10] * y[13]));
        for (int c = 0; c < 3; c++) {
            double a = y[6 + c], b = y[9 + c], g = y[12 + c];
            y[6 + c] = FMA(1.5, a, -(0.5 * FMA(G02, g, FMA(G00, a, G01 * b))));
            y[9 + c] = FMA(1.5, b, -(0.5 * FMA(G12, g, FMA(G01, a, G11 * b))));
            y[12 + c] = FMA(1.5, g, -(0.5 * FMA(G22, g, FMA(G02, a, G12 * b))));
        }
        double error = fmax(fmax(fmax(fabs(G00 - 1.0), fabs(G11 - 1.0)), fmax(fabs(G22 - 1.0),
                       fabs(G01))), fmax(fabs(G02), fabs(G12)));
        if (error <= 1e-8)
            break;
    }
    /* sync_direction (geometric): psi_nu follows the axis azimuth modulo 2 pi */
    if (sqrt(FMA(y[8], y[8], y[11] * y[11])) > 1e-12) {
        double period = 2.0 * PI;
        double psi = atan2(y[11], y[8]);
        y[17] = FMA(period, (double)(long long)rint((y[17] - psi) / period), psi);
    }
    /* project_velocity: project_contact(p, y, True, nu) */
    double n1, n2, n3, nd1, nd2, nd3;
    nu_geometric(y, &n1, &n2, &n3, &nd1, &nd2, &nd3);
    double R = p[0], m = p[1], a3 = p[3], I1 = p[4], I2 = p[5], I3 = p[6];
    double im = 1.0 / m, i1 = 1.0 / I1, i2 = 1.0 / I2, i3 = 1.0 / I3;
    double v1 = y[0], v2 = y[1], v3 = y[2], w1 = y[3], w2 = y[4], w3 = y[5];
    double g1 = y[12], g2 = y[13], g3 = y[14];
    double r1 = -R * g1, r2 = -R * g2, r3 = FMA(-R, g3, -a3);
    double a1 = FMA(r2, g3, -(r3 * g2)), a2 = FMA(r3, g1, -(r1 * g3)),
           a3_ = FMA(r1, g2, -(r2 * g1));
    double c1 = FMA(a3_, w3, FMA(a2, w2, FMA(a1, w1, FMA(g3, v3, FMA(g1, v1, g2 * v2)))));
    double gg = FMA(g3, g3, FMA(g1, g1, g2 * g2));
    double A11 = MASS_ENTRY(gg, a1, a1, a2, a2, a3_, a3_);
    double b1 = FMA(r2, n3, -(r3 * n2)), b2 = FMA(r3, n1, -(r1 * n3)),
           b3 = FMA(r1, n2, -(r2 * n1));
    double c2 = FMA(b3, w3, FMA(b2, w2, FMA(b1, w1, FMA(n3, v3, FMA(n1, v1, n2 * v2)))));
    double gn = FMA(g3, n3, FMA(g1, n1, g2 * n2));
    double A12 = MASS_ENTRY(gn, a1, b1, a2, b2, a3_, b3);
    double nn = FMA(n3, n3, FMA(n1, n1, n2 * n2));
    double A22 = MASS_ENTRY(nn, b1, b1, b2, b2, b3, b3);
    double det = FMA(A11, A22, -(A12 * A12));
    double l1 = FMA(c1, A22, -(c2 * A12)) / det;
    double l2 = FMA(A11, c2, -(A12 * c1)) / det;
    y[0] = FMA(-FMA(l1, g1, l2 * n1), im, v1);
    y[1] = FMA(-FMA(l1, g2, l2 * n2), im, v2);
    y[2] = FMA(-FMA(l1, g3, l2 * n3), im, v3);
    y[3] = FMA(-FMA(l1, a1, l2 * b1), i1, w1);
    y[4] = FMA(-FMA(l1, a2, l2 * b2), i2, w2);
    y[5] = FMA(-FMA(l1, a3_, l2 * b3), i3, w3);
}

/* _compiled/_dop853.py update_track */
static void update_track(double *track, double t, double N_, double T_force)
{
    if (N_ < track[MIN_NORMAL]) {
        track[MIN_NORMAL] = N_;
        track[T_MIN_NORMAL] = t;
    }
    if (N_ < 0.0 && isnan(track[T_CONTACT_LOST]))
        track[T_CONTACT_LOST] = t;
    if (N_ > 0.0) {
        double ratio = T_force / N_;
        if (ratio > track[MAX_RATIO]) {
            track[MAX_RATIO] = ratio;
            track[T_MAX_RATIO] = t;
        }
    }
}

/* ---------------------------------------------------------------- DOP853 stages ------------ */

/* _dop853_stages.py stage: ytmp = y + h * sum_{j<s} A[s, j] K[j], s = 1 .. 15, the sum taken
 * left to right as written there. LLVM's InstCombine rewrites a sum that starts with a negative
 * and a positive term, -a x + b y, as b y - a x, and then fuses the b y: so does the C. */
static void stage(double K[16][N], int s, const double *y, double h, double *ytmp)
{
    int i;
    switch (s) {
    case 1:
        for (i = 0; i < N; i++) {
            ytmp[i] = FMA(h, 0.05260015195876773 * K[0][i], y[i]);
        }
        break;
    case 2:
        for (i = 0; i < N; i++) {
            double a = FMA(0.0197250569845379, K[0][i], 0.0591751709536137 * K[1][i]);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 3:
        for (i = 0; i < N; i++) {
            double a = FMA(0.02958758547680685, K[0][i], 0.08876275643042054 * K[2][i]);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 4:
        for (i = 0; i < N; i++) {
            double a = FMA(0.2413651341592667, K[0][i], -0.8845494793282861 * K[2][i]);
            a = FMA(0.924834003261792, K[3][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 5:
        for (i = 0; i < N; i++) {
            double a = FMA(0.037037037037037035, K[0][i], 0.17082860872947386 * K[3][i]);
            a = FMA(0.12546768756682242, K[4][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 6:
        for (i = 0; i < N; i++) {
            double a = FMA(0.037109375, K[0][i], 0.17025221101954405 * K[3][i]);
            a = FMA(0.06021653898045596, K[4][i], a);
            a = FMA(-0.017578125, K[5][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 7:
        for (i = 0; i < N; i++) {
            double a = FMA(0.03709200011850479, K[0][i], 0.17038392571223998 * K[3][i]);
            a = FMA(0.10726203044637328, K[4][i], a);
            a = FMA(-0.015319437748624402, K[5][i], a);
            a = FMA(0.008273789163814023, K[6][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 8:
        for (i = 0; i < N; i++) {
            double a = FMA(0.6241109587160757, K[0][i], -3.3608926294469414 * K[3][i]);
            a = FMA(-0.868219346841726, K[4][i], a);
            a = FMA(27.59209969944671, K[5][i], a);
            a = FMA(20.154067550477894, K[6][i], a);
            a = FMA(-43.48988418106996, K[7][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 9:
        for (i = 0; i < N; i++) {
            double a = FMA(0.47766253643826434, K[0][i], -2.4881146199716677 * K[3][i]);
            a = FMA(-0.590290826836843, K[4][i], a);
            a = FMA(21.230051448181193, K[5][i], a);
            a = FMA(15.279233632882423, K[6][i], a);
            a = FMA(-33.28821096898486, K[7][i], a);
            a = FMA(-0.020331201708508627, K[8][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 10:
        for (i = 0; i < N; i++) {
            double a = FMA(5.186372428844064, K[3][i], -0.9371424300859873 * K[0][i]); /* swapped */
            a = FMA(1.0914373489967295, K[4][i], a);
            a = FMA(-8.149787010746927, K[5][i], a);
            a = FMA(-18.52006565999696, K[6][i], a);
            a = FMA(22.739487099350505, K[7][i], a);
            a = FMA(2.4936055526796523, K[8][i], a);
            a = FMA(-3.0467644718982196, K[9][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 11:
        for (i = 0; i < N; i++) {
            double a = FMA(2.273310147516538, K[0][i], -10.53449546673725 * K[3][i]);
            a = FMA(-2.0008720582248625, K[4][i], a);
            a = FMA(-17.9589318631188, K[5][i], a);
            a = FMA(27.94888452941996, K[6][i], a);
            a = FMA(-2.8589982771350235, K[7][i], a);
            a = FMA(-8.87285693353063, K[8][i], a);
            a = FMA(12.360567175794303, K[9][i], a);
            a = FMA(0.6433927460157636, K[10][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 12:
        for (i = 0; i < N; i++) {
            double a = FMA(0.054293734116568765, K[0][i], 4.450312892752409 * K[5][i]);
            a = FMA(1.8915178993145003, K[6][i], a);
            a = FMA(-5.801203960010585, K[7][i], a);
            a = FMA(0.3111643669578199, K[8][i], a);
            a = FMA(-0.1521609496625161, K[9][i], a);
            a = FMA(0.20136540080403034, K[10][i], a);
            a = FMA(0.04471061572777259, K[11][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 13:
        for (i = 0; i < N; i++) {
            double a = FMA(0.056167502283047954, K[0][i], 0.25350021021662483 * K[6][i]);
            a = FMA(-0.2462390374708025, K[7][i], a);
            a = FMA(-0.12419142326381637, K[8][i], a);
            a = FMA(0.15329179827876568, K[9][i], a);
            a = FMA(0.00820105229563469, K[10][i], a);
            a = FMA(0.007567897660545699, K[11][i], a);
            a = FMA(-0.008298, K[12][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 14:
        for (i = 0; i < N; i++) {
            double a = FMA(0.03183464816350214, K[0][i], 0.028300909672366776 * K[5][i]);
            a = FMA(0.053541988307438566, K[6][i], a);
            a = FMA(-0.05492374857139099, K[7][i], a);
            a = FMA(-0.00010834732869724932, K[10][i], a);
            a = FMA(0.0003825710908356584, K[11][i], a);
            a = FMA(-0.00034046500868740456, K[12][i], a);
            a = FMA(0.1413124436746325, K[13][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    case 15:
        for (i = 0; i < N; i++) {
            double a = FMA(-0.42889630158379194, K[0][i], -4.697621415361164 * K[5][i]);
            a = FMA(7.683421196062599, K[6][i], a);
            a = FMA(4.06898981839711, K[7][i], a);
            a = FMA(0.3567271874552811, K[8][i], a);
            a = FMA(-0.0013990241651590145, K[12][i], a);
            a = FMA(2.9475147891527724, K[13][i], a);
            a = FMA(-9.15095847217987, K[14][i], a);
            ytmp[i] = FMA(h, a, y[i]);
        }
        break;
    default:
        break;
    }
}

/* _dop853_stages.py scaled_errors: 5th- and 3rd-order error estimates over the scale (the sums
 * fused as in stage, err3's first two terms swapped as there) */
static void scaled_errors(double K[16][N], const double *y, const double *ynew, double rtol,
                          double atol, double *err5, double *err3)
{
    for (int i = 0; i < N; i++) {
        double ay = fabs(y[i]), an = fabs(ynew[i]);
        double sc = FMA(an > ay ? an : ay, rtol, atol);
        double e5 = FMA(0.01312004499419488, K[0][i], -1.2251564463762044 * K[5][i]);
        e5 = FMA(-0.4957589496572502, K[6][i], e5);
        e5 = FMA(1.6643771824549864, K[7][i], e5);
        e5 = FMA(-0.35032884874997366, K[8][i], e5);
        e5 = FMA(0.3341791187130175, K[9][i], e5);
        e5 = FMA(0.08192320648511571, K[10][i], e5);
        e5 = FMA(-0.022355307863886294, K[11][i], e5);
        double e3 = FMA(4.450312892752409, K[5][i], -0.18980075407240762 * K[0][i]); /* swapped */
        e3 = FMA(1.8915178993145003, K[6][i], e3);
        e3 = FMA(-5.801203960010585, K[7][i], e3);
        e3 = FMA(-0.4226823213237919, K[8][i], e3);
        e3 = FMA(-0.1521609496625161, K[9][i], e3);
        e3 = FMA(0.20136540080403034, K[10][i], e3);
        e3 = FMA(0.02265179219836082, K[11][i], e3);
        err5[i] = e5 / sc;
        err3[i] = e3 / sc;
    }
}

/* ---------------------------------------------------------------- dense output ------------- */

/* _dop853_tableau.py D: the 7th-order interpolant's coefficients */
static const double D[4][16] = {
    {-8.428938276109013, 0.0, 0.0, 0.0, 0.0, 0.5667149535193777, -3.0689499459498917,
     2.38466765651207, 2.117034582445028, -0.871391583777973, 2.2404374302607883,
     0.6315787787694688, -0.08899033645133331, 18.148505520854727, -9.194632392478356,
     -4.436036387594894},
    {10.427508642579134, 0.0, 0.0, 0.0, 0.0, 242.28349177525817, 165.20045171727028,
     -374.5467547226902, -22.113666853125306, 7.733432668472264, -30.674084731089398,
     -9.332130526430229, 15.697238121770845, -31.139403219565178, -9.35292435884448,
     35.81684148639408},
    {19.985053242002433, 0.0, 0.0, 0.0, 0.0, -387.0373087493518, -189.17813819516758,
     527.8081592054236, -11.57390253995963, 6.8812326946963, -1.0006050966910838,
     0.7777137798053443, -2.778205752353508, -60.19669523126412, 84.32040550667716,
     11.99229113618279},
    {-25.69393346270375, 0.0, 0.0, 0.0, 0.0, -154.18974869023643, -231.5293791760455,
     357.6391179106141, 93.40532418362432, -37.45832313645163, 104.0996495089623,
     29.8402934266605, -43.53345659001114, 96.32455395918828, -39.17726167561544,
     -149.72683625798564}};

/* _dop853_dense.py prepare_dense: stages 14-16 and the coefficients Fd of the interpolant */
static void prepare_dense(const double *p, double K[16][N], const double *y, const double *ynew,
                          double h, double *ytmp, double Fd[7][N], Reaction *ws)
{
    for (int s = 13; s < 16; s++) {
        stage(K, s, y, h, ytmp);
        rhs(p, ytmp, K[s], ws);
    }
    for (int i = 0; i < N; i++) {
        double dlt = ynew[i] - y[i];
        Fd[0][i] = dlt;
        Fd[1][i] = FMA(h, K[0][i], -dlt);
        Fd[2][i] = FMA(2.0, dlt, -(h * (K[12][i] + K[0][i])));
        for (int r = 0; r < 4; r++) {
            double acc = 0.0;
            for (int j = 0; j < 16; j++)
                acc = FMA(D[r][j], K[j][i], acc);
            Fd[3 + r][i] = h * acc;
        }
    }
}

/* _dop853_dense.py dense_eval: the state at the fraction x of the step; its loop
 * "acc += Fd[r]; acc *= x or 1 - x" for r = 6 .. 0 with each product fused into the next sum */
static void dense_eval(double Fd[7][N], const double *y, double x, double *out)
{
    double xc = 1.0 - x;
    for (int i = 0; i < N; i++) {
        double acc = Fd[6][i] + 0.0;
        acc = FMA(x, acc, Fd[5][i]);
        acc = FMA(xc, acc, Fd[4][i]);
        acc = FMA(x, acc, Fd[3][i]);
        acc = FMA(xc, acc, Fd[2][i]);
        acc = FMA(x, acc, Fd[1][i]);
        acc = FMA(xc, acc, Fd[0][i]);
        out[i] = FMA(x, acc, y[i]);
    }
}

/* _dop853_dense.py normal_root: where N crosses zero in [t, t + h], 60 halvings */
static double normal_root(const double *p, double Fd[7][N], const double *y, double t, double h,
                          double *ytmp, double *dy, Reaction *ws)
{
    double lo = 0.0, hi = 1.0, N_, T_;
    for (int k = 0; k < 60; k++) {
        double mid = 0.5 * (lo + hi);
        dense_eval(Fd, y, mid, ytmp);
        project(p, ytmp);
        rhs(p, ytmp, dy, ws);
        reaction(ytmp, ws, &N_, &T_);
        if (N_ >= 0.0)
            lo = mid;
        else
            hi = mid;
    }
    return FMA(0.5 * (lo + hi), h, t);
}

/* ---------------------------------------------------------------- the integrator ----------- */

/* _dop853.py initial_step (Hairer, Norsett & Wanner, Sec. II.4, as in SciPy) */
static double initial_step(const double *p, const double *y, const double *f, double t_end,
                           double t0, double rtol, double atol, double *ytmp, double *ftmp,
                           Reaction *ws)
{
    double d0 = 0.0, d1 = 0.0, d2 = 0.0;
    int i;
    for (i = 0; i < N; i++) {
        double sc = FMA(fabs(y[i]), rtol, atol);
        double a = y[i] / sc, b = f[i] / sc;
        d0 = FMA(a, a, d0);
        d1 = FMA(b, b, d1);
    }
    d0 = sqrt(d0 / N);
    d1 = sqrt(d1 / N);
    if (!(isfinite(d0) && isfinite(d1)))
        return NAN;
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (t_end - t0 < h0)
        h0 = t_end - t0;
    for (i = 0; i < N; i++)
        ytmp[i] = FMA(h0, f[i], y[i]);
    rhs(p, ytmp, ftmp, ws);
    for (i = 0; i < N; i++) {
        double sc = FMA(fabs(y[i]), rtol, atol);
        double a = (ftmp[i] - f[i]) / sc;
        d2 = FMA(a, a, d2);
    }
    d2 = sqrt(d2 / N) / h0;
    double h1;
    if (d1 <= 1e-15 && d2 <= 1e-15)
        h1 = fmax(1e-6, h0 * 1e-3);
    else
        h1 = pow(0.01 / (d1 > d2 ? d1 : d2), 1.0 / 8.0);
    double h = 100.0 * h0;
    if (h1 < h)
        h = h1;
    if (t_end - t0 < h)
        h = t_end - t0;
    return h;
}

static int all_finite(const double *a, const double *b)
{
    for (int i = 0; i < N; i++)
        if (!isfinite(a[i]) || !isfinite(b[i]))
            return 0;
    return 1;
}

/*
 * rt_integrate: integrate the meridian model (geometric nu, rollingtop's kernel code 0) with
 * DOP853 from y at t_eval[0] to t_eval[n_samples - 1], as rollingtop.integrate.driver.integrate
 * does (without events), projecting the state onto the constraints and monitoring the contact
 * reaction after every accepted step.
 *
 *   p          the 7 body parameters (R, m, g, a3, I1, I2, I3)
 *   y          the 18-component initial state (constraint-consistent); on return the state at the
 *              last accepted step (projected), i.e. at the end of the integration
 *   t_eval     n_samples >= 2 strictly increasing sample times
 *   out        n_samples x 18 (row-major): the samples from the dense output, each projected,
 *              as rollingtop's IntegrationResult.y (out[0] = the initial state)
 *   rtol, atol tolerances of the error control
 *   stats      3 longs: accepted steps, rejected steps, right-hand-side evaluations (counted as
 *              rollingtop counts them)
 *   track      6 doubles (as rollingtop's reaction tracking): min normal force, its time, time of
 *              the first loss of contact (NaN: none), max friction ratio, its time, last normal
 *              force
 *
 * Returns rollingtop's status codes: 0 finished, -1 step size underflow, -2 non-finite state,
 * -3 too many rejected steps in a row.
 */
int rt_integrate(const double *p, double *y, const double *t_eval, long n_samples, double *out,
                 double rtol, double atol, long *stats, double *track)
{
    double K[16][N], Fd[7][N];
    double f[N], ynew[N], ytmp[N], y_old[N];
    Reaction ws;
    long steps = 0, n_rejected = 0, nfev = 0;
    int i, status = FINISHED;

    /* start */
    rhs(p, y, f, &ws);
    track[MIN_NORMAL] = INFINITY;
    track[T_MIN_NORMAL] = NAN;
    track[T_CONTACT_LOST] = NAN;
    track[MAX_RATIO] = 0.0;
    track[T_MAX_RATIO] = NAN;
    track[LAST_NORMAL] = NAN;
    double N0, T0;
    reaction(y, &ws, &N0, &T0);
    update_track(track, t_eval[0], N0, T0);
    track[LAST_NORMAL] = N0;
    double t = t_eval[0], t_end = t_eval[n_samples - 1];
    double h_abs = initial_step(p, y, f, t_end, t, rtol, atol, ytmp, ynew, &ws);
    nfev = 2;
    for (i = 0; i < N; i++)
        out[i] = y[i];
    long next_sample = 1;

    /* run */
    if (!all_finite(y, f)) {
        status = NOT_FINITE;
        goto done;
    }
    while (t < t_end) {
        double min_step = 10.0 * fabs(nextafter(t, INFINITY) - t);
        int rejected = 0;
        double t_new, h;
        for (;;) {
            if (!(h_abs >= min_step)) {
                status = STEP_TOO_SMALL;
                goto done;
            }
            t_new = t + h_abs;
            if (t_new > t_end)
                t_new = t_end;
            h = t_new - t;
            for (i = 0; i < N; i++)
                K[0][i] = f[i];
            for (int s = 1; s < 12; s++) {
                stage(K, s, y, h, ytmp);
                rhs(p, ytmp, K[s], &ws);
            }
            stage(K, 12, y, h, ynew);
            rhs(p, ynew, K[12], &ws);
            nfev += 12;
            double *err5 = Fd[0], *err3 = Fd[1];
            scaled_errors(K, y, ynew, rtol, atol, err5, err3);
            double e5 = 0.0, e3 = 0.0, err;
            for (i = 0; i < N; i++) {
                e5 = FMA(err5[i], err5[i], e5);
                e3 = FMA(err3[i], err3[i], e3);
            }
            if (e5 == 0.0 && e3 == 0.0)
                err = 0.0;
            else
                err = h * e5 / sqrt(FMA(0.01, e3, e5) * N);
            if (!isfinite(err)) {
                h_abs *= MIN_FACTOR;
                n_rejected++;
                rejected++;
                if (rejected >= MAX_REJECTED_IN_A_ROW) {
                    status = NOT_FINITE;
                    goto done;
                }
            } else if (err < 1.0) {
                double factor;
                if (err == 0.0)
                    factor = MAX_FACTOR;
                else {
                    factor = SAFETY * pow(err, ERROR_EXPONENT);
                    if (factor > MAX_FACTOR)
                        factor = MAX_FACTOR;
                }
                if (rejected > 0 && factor > 1.0)
                    factor = 1.0;
                h_abs *= factor;
                break;
            } else {
                double factor = SAFETY * pow(err, ERROR_EXPONENT);
                if (factor < MIN_FACTOR)
                    factor = MIN_FACTOR;
                h_abs *= factor;
                n_rejected++;
                rejected++;
                if (rejected >= MAX_REJECTED_IN_A_ROW) {
                    status = TOO_MANY_REJECTED;
                    goto done;
                }
            }
        }
        /* contact reaction at the new point, from the last stage (FSAL) */
        double N_, T_force;
        reaction(ynew, &ws, &N_, &T_force);
        /* dense output for the samples in [t, t_new] */
        int dense_ready = 0;
        if (next_sample < n_samples && t_eval[next_sample] <= t_new) {
            prepare_dense(p, K, y, ynew, h, ytmp, Fd, &ws);
            nfev += 3;
            dense_ready = 1;
            while (next_sample < n_samples && t_eval[next_sample] <= t_new) {
                double *o = out + next_sample * N;
                dense_eval(Fd, y, (t_eval[next_sample] - t) / h, o);
                project(p, o);
                next_sample++;
            }
        }
        /* accept: project onto the constraints; the derivative is the last stage (FSAL) */
        for (i = 0; i < N; i++) {
            y_old[i] = y[i];
            y[i] = ynew[i];
            f[i] = K[12][i];
        }
        project(p, y);
        if (!all_finite(y, f)) {
            t = t_new;
            status = NOT_FINITE;
            goto done;
        }
        if (N_ < 0.0 && isnan(track[T_CONTACT_LOST]) && track[LAST_NORMAL] >= 0.0) {
            if (!dense_ready) {
                prepare_dense(p, K, y_old, ynew, h, ytmp, Fd, &ws);
                nfev += 3;
                dense_ready = 1;
            }
            track[T_CONTACT_LOST] = normal_root(p, Fd, y_old, t, h, ytmp, K[13], &ws);
            nfev += 60;
        }
        track[LAST_NORMAL] = N_;
        update_track(track, t_new, N_, T_force);
        t = t_new;
        steps++;
    }
done:
    stats[0] = steps;
    stats[1] = n_rejected;
    stats[2] = nfev;
    return status;
}

/* ---------------------------------------------------------------- checks ------------------- */

/* The pieces one by one, for the bit-for-bit comparison with rollingtop's compiled functions
 * (benchmarks/c_limit.py --check). K is 16 x 18 and Fd 7 x 18, row-major. */

double rt_rhs(const double *p, const double *y, double *dy)
{
    Reaction ws;
    double N_, T_;
    rhs(p, y, dy, &ws);
    reaction(y, &ws, &N_, &T_);
    return N_;
}

void rt_project(const double *p, double *y) { project(p, y); }

void rt_stage(double *K, int s, const double *y, double h, double *ytmp)
{
    stage((double(*)[N])K, s, y, h, ytmp);
}

void rt_scaled_errors(double *K, const double *y, const double *ynew, double rtol, double atol,
                      double *err5, double *err3)
{
    scaled_errors((double(*)[N])K, y, ynew, rtol, atol, err5, err3);
}

void rt_prepare_dense(const double *p, double *K, const double *y, const double *ynew, double h,
                      double *Fd)
{
    Reaction ws;
    double ytmp[N];
    prepare_dense(p, (double(*)[N])K, y, ynew, h, ytmp, (double(*)[N])Fd, &ws);
}

void rt_dense_eval(double *Fd, const double *y, double x, double *out)
{
    dense_eval((double(*)[N])Fd, y, x, out);
}

double rt_initial_step(const double *p, const double *y, const double *f, double t_end, double t0,
                       double rtol, double atol)
{
    Reaction ws;
    double ytmp[N], ftmp[N];
    return initial_step(p, y, f, t_end, t0, rtol, atol, ytmp, ftmp, &ws);
}
