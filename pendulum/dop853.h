// Internal to pendulum/: an explicit Runge-Kutta 8(5,3) integrator with 7th-order dense output
// for small, non-stiff systems of fixed size, used by integrator.cc. The method is Dormand and
// Prince's DOP853 as published by Hairer, Norsett and Wanner, "Solving Ordinary Differential
// Equations I", 2nd ed., Springer 1993, section II.10 (coefficients of their code dop853.f):
// 12 stages for the step, a 5th- and a 3rd-order embedded error estimate combined as in
// dop853.f, and 3 extra stages for the dense output. Everything is inlined on fixed-size
// arrays: for a 12-state system this costs a fraction of a microsecond per step, where a general
// solver's vector abstraction costs several.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace bifilar {
namespace dop853 {

constexpr int kStages = 12;
constexpr int kStagesDense = 16;

constexpr double kC[kStagesDense] = {
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
};

// Lower-triangular stage matrix; row 12 is the solution weights b, rows 13-15 the dense-output
// stages.
constexpr double kA[kStagesDense][kStagesDense] = {
    {},
    {5.26001519587677318785587544488e-2},
    {1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2},
    {2.95875854768068491816892993775e-2, 0.0, 8.87627564304205475450678981324e-2},
    {2.41365134159266685502369798665e-1, 0.0, -8.84549479328286085344864962717e-1,
     9.24834003261792003115737966543e-1},
    {3.7037037037037037037037037037e-2, 0.0, 0.0, 1.70828608729473871279604482173e-1,
     1.25467687566822425016691814123e-1},
    {3.7109375e-2, 0.0, 0.0, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2,
     -1.7578125e-2},
    {3.70920001185047927108779319836e-2, 0.0, 0.0, 1.70383925712239993810214054705e-1,
     1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2,
     8.27378916381402288758473766002e-3},
    {6.24110958716075717114429577812e-1, 0.0, 0.0, -3.36089262944694129406857109825,
     -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1,
     2.01540675504778934086186788979e1, -4.34898841810699588477366255144e1},
    {4.77662536438264365890433908527e-1, 0.0, 0.0, -2.48811461997166764192642586468,
     -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1,
     1.52792336328824235832596922938e1, -3.32882109689848629194453265587e1,
     -2.03312017085086261358222928593e-2},
    {-9.3714243008598732571704021658e-1, 0.0, 0.0, 5.18637242884406370830023853209,
     1.09143734899672957818500254654, -8.14978701074692612513997267357,
     -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1,
     2.49360555267965238987089396762, -3.0467644718982195003823669022},
    {2.27331014751653820792359768449, 0.0, 0.0, -1.05344954667372501984066689879e1,
     -2.00087205822486249909675718444, -1.79589318631187989172765950534e1,
     2.79488845294199600508499808837e1, -2.85899827713502369474065508674,
     -8.87285693353062954433549289258, 1.23605671757943030647266201528e1,
     6.43392746015763530355970484046e-1},
    {5.42937341165687622380535766363e-2, 0.0, 0.0, 0.0, 0.0, 4.45031289275240888144113950566,
     1.89151789931450038304281599044, -5.8012039600105847814672114227,
     3.1116436695781989440891606237e-1, -1.52160949662516078556178806805e-1,
     2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2},
    {5.61675022830479523392909219681e-2, 0.0, 0.0, 0.0, 0.0, 0.0,
     2.53500210216624811088794765333e-1, -2.46239037470802489917441475441e-1,
     -1.24191423263816360469010140626e-1, 1.5329179827876569731206322685e-1,
     8.20105229563468988491666602057e-3, 7.56789766054569976138603589584e-3, -8.298e-3},
    {3.18346481635021405060768473261e-2, 0.0, 0.0, 0.0, 0.0, 2.83009096723667755288322961402e-2,
     5.35419883074385676223797384372e-2, -5.49237485713909884646569340306e-2, 0.0, 0.0,
     -1.08347328697249322858509316994e-4, 3.82571090835658412954920192323e-4,
     -3.40465008687404560802977114492e-4, 1.41312443674632500278074618366e-1},
    {-4.28896301583791923408573538692e-1, 0.0, 0.0, 0.0, 0.0, -4.69762141536116384314449447206,
     7.68342119606259904184240953878, 4.06898981839711007970213554331,
     3.56727187455281109270669543021e-1, 0.0, 0.0, 0.0, -1.39902416515901462129418009734e-3,
     2.9475147891527723389556272149, -9.15095847217987001081870187138},
};

// 5th-order error weights (b - bhat5) and 3rd-order ones (b - bhat3), stages 0-11.
constexpr double kE5[kStages] = {
    0.1312004499419488073250102996e-1,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e1,
    -0.4957589496572501915214079952,
    0.1664377182454986536961530415e1,
    -0.3503288487499736816886487290,
    0.3341791187130174790297318841,
    0.8192320648511571246570742613e-1,
    -0.2235530786388629525884427845e-1,
};
constexpr double kBhat3Diff0 = 0.244094488188976377952755905512;      // E3[0] = b0 - this
constexpr double kBhat3Diff8 = 0.733846688281611857341361741547;      // E3[8] = b8 - this
constexpr double kBhat3Diff11 = 0.220588235294117647058823529412e-1;  // E3[11] = b11 - this

// Dense output: rows 3-6 of the interpolant's coefficients, as weights of the 16 stages.
constexpr double kD[4][kStagesDense] = {
    {-0.84289382761090128651353491142e1, 0.0, 0.0, 0.0, 0.0, 0.56671495351937776962531783590,
     -0.30689499459498916912797304727e1, 0.23846676565120698287728149680e1,
     0.21170345824450282767155149946e1, -0.87139158377797299206789907490,
     0.22404374302607882758541771650e1, 0.63157877876946881815570249290,
     -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e2,
     -0.91946323924783554000451984436e1, -0.44360363875948939664310572000e1},
    {0.10427508642579134603413151009e2, 0.0, 0.0, 0.0, 0.0, 0.24228349177525818288430175319e3,
     0.16520045171727028198505394887e3, -0.37454675472269020279518312152e3,
     -0.22113666853125306036270938578e2, 0.77334326684722638389603898808e1,
     -0.30674084731089398182061213626e2, -0.93321305264302278729567221706e1,
     0.15697238121770843886131091075e2, -0.31139403219565177677282850411e2,
     -0.93529243588444783865713862664e1, 0.35816841486394083752465898540e2},
    {0.19985053242002433820987653617e2, 0.0, 0.0, 0.0, 0.0, -0.38703730874935176555105901742e3,
     -0.18917813819516756882830838328e3, 0.52780815920542364900561016686e3,
     -0.11573902539959630126141871134e2, 0.68812326946963000169666922661e1,
     -0.10006050966910838403183860980e1, 0.77771377980534432092869265740,
     -0.27782057523535084065932004339e1, -0.60196695231264120758267380846e2,
     0.84320405506677161018159903784e2, 0.11992291136182789328035130030e2},
    {-0.25693933462703749003312586129e2, 0.0, 0.0, 0.0, 0.0, -0.15418974869023643374053993627e3,
     -0.23152937917604549567536039109e3, 0.35763911791061412378285349910e3,
     0.93405324183624310003907691704e2, -0.37458323136451633156875139351e2,
     0.10409964950896230045147246184e3, 0.29840293426660503123344363579e2,
     -0.43533456590011143754432175058e2, 0.96324553959188282948394950600e2,
     -0.39177261675615439165231486172e2, -0.14972683625798562581422125276e3},
};

struct Stats {
  long steps = 0;     // attempted steps
  long rejected = 0;  // of which rejected
  long rhs_evals = 0;
};

// One adaptive integration over an increasing sequence of output times. Rhs is a callable
// bool(const double* y, double* dy) (false: the state is outside the model's domain or not
// finite; the step is retried smaller). Out is a callable void(int k, const double* y) called
// once per output time t_out[k], k = first..count-1, with the 7th-order dense-output state.
// Kink is a callable double(const double* y, const double* f, const double* f_prev,
// double h_prev) returning the (estimated) time from the state y, with derivative f, to the
// next point where the right-hand side is not smooth, or +inf. A step that would cross such a
// point fails the error test again and again (the method's order needs a smooth solution), so
// steps are cut to end there instead; the estimate need not be exact, as a kink a small
// fraction of a step inside costs little accuracy.
template <int N>
class Stepper {
 public:
  using Vec = std::array<double, N>;

  // Returns 0 on success, 1 when max_steps was exceeded, 2 when the step size underflowed
  // (repeated non-finite right-hand sides or error test failures); *t_fail is then the time
  // reached.
  template <typename Rhs, typename Out, typename Kink>
  int Integrate(Rhs&& rhs, double t0, const Vec& y0, const double* t_out, int first, int count,
                double rel_tol, double abs_tol, long max_steps, Out&& out, Kink&& kink,
                double* t_fail, Stats* stats) {
    Stats st;
    double t = t0;
    Vec y = y0;
    Vec k[kStagesDense];
    auto scale = [&](double a, double b) {
      return abs_tol + rel_tol * std::max(std::abs(a), std::abs(b));
    };
    if (!rhs(y.data(), k[0].data())) {
      *t_fail = t;
      return 2;
    }
    ++st.rhs_evals;
    const double t_end = t_out[count - 1];
    double h = InitialStep(rhs, t, y, k[0], t_end - t, rel_tol, abs_tol, &st);
    int next = first;
    bool rejected_last = false;
    double h_after_kink = 0.0;  // > 0: the step proposed before it was cut at a kink
    Vec y_new, f_new;
    Vec F[7];
    while (next < count) {
      if (st.steps >= max_steps) {
        *t_fail = t;
        if (stats != nullptr) *stats = st;
        return 1;
      }
      ++st.steps;
      const double h_min =
          16.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t));
      if (!(h > h_min)) {
        *t_fail = t;
        if (stats != nullptr) *stats = st;
        return 2;
      }
      bool last = false;
      // The last step to t_end, also when only a sliver (< 1 % of h) would remain after this one.
      if (t + 1.01 * h >= t_end) {
        h = t_end - t;
        last = true;
      }
      // Stages 1..11 and the solution.
      bool finite = true;
      for (int s = 1; s < kStages && finite; ++s) {
        Vec ys;
        Combine(s, s, h, y, k, &ys);
        finite = rhs(ys.data(), k[s].data());
        ++st.rhs_evals;
      }
      if (finite) Combine(12, kStages, h, y, k, &y_new);
      // Error: dop853.f's combination of the 5th- and 3rd-order estimates.
      double err = 2.0;  // rejected when a stage was not finite
      if (finite) {
        double err5 = 0.0, err3 = 0.0;
        Vec e5{}, e3;
        for (int j = 0; j < kStages; ++j) {
          if (kE5[j] == 0.0) continue;
          for (int i = 0; i < N; ++i) e5[i] += kE5[j] * k[j][i];
        }
        for (int i = 0; i < N; ++i) {
          // b . k = (y_new - y) / h.
          e3[i] = (y_new[i] - y[i]) / h - kBhat3Diff0 * k[0][i] - kBhat3Diff8 * k[8][i] -
                  kBhat3Diff11 * k[11][i];
        }
        for (int i = 0; i < N; ++i) {
          const double sk = scale(y[i], y_new[i]);
          err5 += (e5[i] / sk) * (e5[i] / sk);
          err3 += (e3[i] / sk) * (e3[i] / sk);
        }
        double deno = err5 + 0.01 * err3;
        if (deno <= 0.0) deno = 1.0;
        err = std::abs(h) * err5 / std::sqrt(N * deno);
        if (!std::isfinite(err)) err = 2.0;
      }
      if (err > 1.0) {
        ++st.rejected;
        rejected_last = true;
        // Shrink: 0.9 err^(-1/8), at least by 3 (and always by 4 after a non-finite stage).
        const double fac = finite ? std::max(1.0 / 3.0, 0.9 * std::pow(err, -0.125)) : 0.25;
        h *= std::min(fac, 0.9);
        continue;
      }
      if (!rhs(y_new.data(), f_new.data())) {  // the step landed outside the domain
        ++st.rejected;
        rejected_last = true;
        h *= 0.25;
        continue;
      }
      ++st.rhs_evals;
      k[12] = f_new;
      const double t_new = last ? t_end : t + h;
      // Dense output when an output time falls in (t, t_new].
      if (t_out[next] <= t_new) {
        bool dense_ok = true;
        for (int s = 13; s < kStagesDense && dense_ok; ++s) {
          Vec ys;
          Combine(s, s, h, y, k, &ys);
          dense_ok = rhs(ys.data(), k[s].data());
          ++st.rhs_evals;
        }
        if (!dense_ok) {
          ++st.rejected;
          rejected_last = true;
          h *= 0.25;
          continue;
        }
        for (int i = 0; i < N; ++i) {
          const double dy = y_new[i] - y[i];
          F[0][i] = dy;
          F[1][i] = h * k[0][i] - dy;
          F[2][i] = 2.0 * dy - h * (f_new[i] + k[0][i]);
        }
        for (int r = 0; r < 4; ++r) {
          Vec acc{};
          for (int j = 0; j < kStagesDense; ++j) {
            if (kD[r][j] == 0.0) continue;
            const double d = kD[r][j];
            for (int i = 0; i < N; ++i) acc[i] += d * k[j][i];
          }
          for (int i = 0; i < N; ++i) F[3 + r][i] = h * acc[i];
        }
        Vec yo;
        while (next < count && t_out[next] <= t_new) {
          if (t_out[next] == t_new) {
            out(next, y_new.data());
          } else {
            const double x = (t_out[next] - t) / h, x1 = 1.0 - x;
            for (int i = 0; i < N; ++i) {
              double v = F[6][i] * x;
              v = (v + F[5][i]) * x1;
              v = (v + F[4][i]) * x;
              v = (v + F[3][i]) * x1;
              v = (v + F[2][i]) * x;
              v = (v + F[1][i]) * x1;
              v = (v + F[0][i]) * x;
              yo[i] = y[i] + v;
            }
            out(next, yo.data());
          }
          ++next;
        }
      }
      // Step size for the next step: 0.9 err^(-1/8), growth limited to 6, shrink to 1/3.
      // No growth right after a rejection (dop853.f).
      const double fac = err > 0.0 ? 0.9 * std::pow(err, -0.125) : 6.0;
      double h_next = h * std::min(rejected_last ? 1.0 : 6.0, std::max(1.0 / 3.0, fac));
      if (h_after_kink > 0.0) {
        // This step was cut at a kink: resume with the step proposed before the cut.
        h_next = std::max(h_next, h_after_kink);
        h_after_kink = 0.0;
      }
      rejected_last = false;
      const double to_kink = kink(y_new.data(), f_new.data(), k[0].data(), h);
      if (to_kink > 0.01 * h_next && to_kink < h_next) {
        h_after_kink = h_next;
        h_next = to_kink;
      }
      t = t_new;
      y = y_new;
      k[0] = f_new;
      h = h_next;
    }
    if (stats != nullptr) *stats = st;
    return 0;
  }

 private:
  // *out = y + h sum_{j < count} kA[row][j] k[j], skipping the tableau's zeros.
  static void Combine(int row, int count, double h, const Vec& y, const Vec* k, Vec* out) {
    Vec acc{};
    for (int j = 0; j < count; ++j) {
      const double a = kA[row][j];
      if (a == 0.0) continue;
      for (int i = 0; i < N; ++i) acc[i] += a * k[j][i];
    }
    for (int i = 0; i < N; ++i) (*out)[i] = y[i] + h * acc[i];
  }

  // Hairer's starting step (Solving ODEs I, II.4): h0 from |y| / |f|, refined with a second
  // derivative estimate, h = (0.01 / max(|f|, |f'|))^(1/8).
  template <typename Rhs>
  double InitialStep(Rhs& rhs, double /*t*/, const Vec& y, const Vec& f, double span,
                     double rel_tol, double abs_tol, Stats* st) {
    double d0 = 0.0, d1 = 0.0;
    for (int i = 0; i < N; ++i) {
      const double sk = abs_tol + rel_tol * std::abs(y[i]);
      d0 += (y[i] / sk) * (y[i] / sk);
      d1 += (f[i] / sk) * (f[i] / sk);
    }
    d0 = std::sqrt(d0 / N);
    d1 = std::sqrt(d1 / N);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = std::min(h0, span);
    Vec y1, f1;
    for (int i = 0; i < N; ++i) y1[i] = y[i] + h0 * f[i];
    if (!rhs(y1.data(), f1.data())) return h0;
    ++st->rhs_evals;
    double d2 = 0.0;
    for (int i = 0; i < N; ++i) {
      const double sk = abs_tol + rel_tol * std::abs(y[i]);
      d2 += ((f1[i] - f[i]) / sk) * ((f1[i] - f[i]) / sk);
    }
    d2 = std::sqrt(d2 / N) / h0;
    const double dm = std::max(d1, d2);
    const double h1 = dm <= 1e-15 ? std::max(1e-6, h0 * 1e-3) : std::pow(0.01 / dm, 1.0 / 8.0);
    return std::min({100.0 * h0, h1, span});
  }
};

}  // namespace dop853
}  // namespace bifilar
