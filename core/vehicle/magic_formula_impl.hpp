// The body of magic_formula<S> (declared in magic_formula.hpp, which includes this file): kept in a
// header so that any AutoDiffScalar derivative type can be used; double and
// AutoDiffScalar<VectorXd> are compiled once in magic_formula.cpp. The equations follow MFeval 4.0's
// Solver, equation by equation and in its order of operations (so that doubles agree with its
// tables to round-off); the equation numbers are Pacejka's (4.Exx, 3rd ed.) or the Besselink,
// Schmeitz and Pacejka 2010 paper's (Axx).
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "vehicle/magic_formula.hpp"

namespace codyna {

namespace mf_detail {

constexpr double mf_pi = 3.14159265358979323846;
constexpr double mf_eps = 1e-6;  // MFeval's epsilon (epsilonx, epsilony, epsilonk, epsilonv)

// The slip-dependent quantities shared by the calculations.
template <class S>
struct MfState {
  S Fz, Fz_mz, uFz, kappa, ukappa, alpha, gamma, Vcx, p;  // inputs after the limits; u: before
  S dfz, dpi, Fz0p, cos_alpha_prime;
  bool low_speed = false;
  S red_smooth;  // the low-speed reduction factor of the shifts (1 above VXLOW)
};

template <class S>
struct MfLateral {
  S Fy0, muy, Kya, SHy, SVy, By, Cy;
};

}  // namespace mf_detail

template <class S>
TireForces<S> magic_formula(const MagicFormulaParameters& P, const TireInput<S>& in, const MagicFormulaOptions& options) {
  using std::abs;
  using std::cos;
  using std::exp;
  using std::pow;
  using std::sin;
  using std::sqrt;
  using std::tan;
  constexpr bool is_double = std::is_same_v<S, double>;
  const double eps = mf_detail::mf_eps;
  const double pi = mf_detail::mf_pi;

  // derivative vectors of one size everywhere (Eigen's AutoDiff sums of unevaluated expressions
  // need them coherent): constants and unseeded inputs get zeros of the seeded inputs' size
  Eigen::Index nd = 0;
  if constexpr (!is_double) {
    for (const S* x : {&in.Fz, &in.kappa, &in.alpha, &in.gamma, &in.phit, &in.Vx, &in.pressure})
      nd = std::max<Eigen::Index>(nd, x->derivatives().size());
  }
  auto K = [&](double v) -> S {
    if constexpr (is_double) return v;
    else return S(v, S::DerType::Zero(nd));
  };
  auto coh = [&](S x) -> S {
    if constexpr (!is_double)
      if (x.derivatives().size() != nd) x.derivatives() = S::DerType::Zero(nd);
    return x;
  };
  auto val = [](const S& x) { return tire_value(x); };
  auto atan_ = [](const S& x) -> S { return tire_atan(x); };
  auto sin_ = [](const S& x) -> S { return sin(x); };
  auto cos_ = [](const S& x) -> S { return cos(x); };
  auto tan_ = [](const S& x) -> S { return tan(x); };
  auto exp_ = [](const S& x) -> S { return exp(x); };
  auto abs_ = [](const S& x) -> S { return abs(x); };
  auto sq = [](const S& x) -> S { return x * x; };

  // mirroring when mounted on the other side than the file describes
  const bool mirror = (options.mount == TireMount::Left && P.TYRESIDE == TireSide::Right) ||
                      (options.mount == TireMount::Right && P.TYRESIDE == TireSide::Left);
  const double ms = mirror ? -1.0 : 1.0;

  // ---- parseInputs: limits and the low-speed model
  mf_detail::MfState<S> st;
  S Fz = coh(in.Fz);
  if (val(Fz) < 0) Fz = K(0.0);
  S kappa = coh(in.kappa);
  S alpha = coh(in.alpha) * ms;
  S gamma = coh(in.gamma) * ms;
  const S Vcx = coh(in.Vx);
  st.uFz = Fz;
  st.ukappa = kappa;
  S p = val(in.pressure) > 0 ? coh(in.pressure) : K(P.INFLPRES);
  S Fz_low = Fz;
  st.red_smooth = K(1.0);
  if (options.limits) {
    const double VXLOW = P.VXLOW;
    st.low_speed = std::abs(val(Vcx)) <= VXLOW && VXLOW > 0;
    if (st.low_speed) {
      const S Wvlow = 0.5 * (1.0 + cos_(pi * (Vcx / VXLOW)));
      st.red_smooth = 1.0 - Wvlow;
      const S red_linear = abs_(Vcx / VXLOW);
      kappa = kappa * red_linear;
    }
    const S Vsy = tan_(alpha) * Vcx;
    const S speed_sum = abs_(Vcx) + abs_(Vsy);
    if (val(speed_sum) < VXLOW) alpha = alpha * (speed_sum / VXLOW);
    if (val(alpha) < P.ALPMIN) alpha = K(P.ALPMIN);
    if (val(alpha) > P.ALPMAX) alpha = K(P.ALPMAX);
    if (val(gamma) < P.CAMMIN) gamma = K(P.CAMMIN);
    if (val(gamma) > P.CAMMAX) gamma = K(P.CAMMAX);
    if (val(Fz) > P.FZMAX) Fz = K(P.FZMAX);
    Fz_low = Fz;
    if (val(Fz) < P.FZMIN) Fz_low = K(P.FZMIN);
    if (val(p) < P.PRESMIN) p = K(P.PRESMIN);
    if (val(p) > P.PRESMAX) p = K(P.PRESMAX);
    if (val(kappa) < P.KPUMIN) kappa = K(P.KPUMIN);
    if (val(kappa) > P.KPUMAX) kappa = K(P.KPUMAX);
  }
  st.Fz = Fz;
  st.kappa = kappa;
  st.alpha = alpha;
  st.gamma = gamma;
  st.Vcx = Vcx;
  st.p = p;
  st.Fz_mz = options.limits ? (val(Fz) <= 0 ? K(0.0) : Fz_low) : Fz;
  const bool mf52 = P.version == MagicFormulaVersion::MF52;

  // ---- calculateBasic
  const double Fz0 = P.FNOMIN, R0 = P.UNLOADED_RADIUS, V0 = P.LONGVL;
  const double Fz0p = P.LFZO * Fz0;  // (4.E1)
  const S dfz = (Fz - Fz0p) / Fz0p;  // (4.E2a)
  const S dpi = (p - P.NOMPRES) / P.NOMPRES;  // (4.E2b)
  const S& alpha_star = alpha;  // no alpha_star definition (MFeval's use mode x1x)
  const S& gamma_star = gamma;
  {
    const S Vcy = tan_(alpha) * abs_(Vcx);  // (2.12)
    const S Vc2 = Vcx * Vcx + Vcy * Vcy;
    const S Vc = val(Vc2) > 0 ? S(sqrt(Vc2)) : K(0.0);
    const S Vc_prime = Vc + eps * tire_sign_nz(Vc);  // (4.E6a)
    st.cos_alpha_prime = Vcx / Vc_prime;             // cos of alpha' = acos(Vcx / Vc') (4.E6)
  }
  const double LMUX = P.LMUX, LMUY = P.LMUY;  // LMUV = 0, Amu = 1: the starred and primed scalings equal these

  // ---- calculateFx0: pure longitudinal slip
  const double Cx = P.PCX1 * P.LCX;  // (4.E11)
  S mux = (P.PDX1 + P.PDX2 * dfz) * (1.0 + P.PPX3 * dpi + P.PPX4 * sq(dpi)) * (1.0 - P.PDX3 * sq(gamma)) * LMUX;  // (4.E13)
  if (val(Fz) == 0) mux = K(0.0);
  const S Dx = mux * Fz;                                                                                          // (4.E12)
  const S Kxk = Fz * (P.PKX1 + P.PKX2 * dfz) * exp_(P.PKX3 * dfz) * (1.0 + P.PPX1 * dpi + P.PPX2 * sq(dpi)) * P.LKX;  // (4.E15)
  const S Bx = Kxk / (Cx * Dx + eps * tire_sign_nz(Dx));  // (4.E16)
  S SHx = (P.PHX1 + P.PHX2 * dfz) * P.LHX;                 // (4.E17)
  S SVx = Fz * (P.PVX1 + P.PVX2 * dfz) * P.LVX * LMUX;      // (4.E18)
  if (st.low_speed) {
    SVx = SVx * st.red_smooth;
    SHx = SHx * st.red_smooth;
  }
  const S kappax = kappa + SHx;  // (4.E10)
  S Ex = (P.PEX1 + P.PEX2 * dfz + P.PEX3 * sq(dfz)) * (1.0 - P.PEX4 * tire_sign(kappax)) * P.LEX;  // (4.E14)
  if (options.limits && val(Ex) > 1) Ex = K(1.0);
  S Fx0;
  {
    const S Bk = Bx * kappax;
    Fx0 = Dx * sin_(Cx * atan_(Bk - Ex * (Bk - atan_(Bk)))) + SVx;  // (4.E9)
  }
  if (val(Vcx) < 0) Fx0 = -Fx0;

  // ---- calculateFy0: pure lateral slip, for a camber gamma_star (the Mz calculation asks for 0)
  auto lateral = [&](const S& gs) -> mf_detail::MfLateral<S> {
    mf_detail::MfLateral<S> r;
    r.Kya = P.PKY1 * Fz0p * (1.0 + P.PPY1 * dpi) * (1.0 - P.PKY3 * abs_(gs)) *
            sin_(P.PKY4 * atan_((Fz / Fz0p) / ((P.PKY2 + P.PKY5 * sq(gs)) * (1.0 + P.PPY2 * dpi)))) * P.LKY;  // (4.E25)
    const S SVyg = Fz * (P.PVY3 + P.PVY4 * dfz) * gs * P.LKYC * LMUY;  // (4.E28)
    if (mf52) {
      r.SHy = (P.PHY1 + P.PHY2 * dfz) * P.LHY + P.PHY3 * gs * P.LKYC;  // MF-Tyre 5.2 manual
    } else {
      const S Kyg0 = Fz * (P.PKY6 + P.PKY7 * dfz) * (1.0 + P.PPY5 * dpi) * P.LKYC;  // (4.E30)
      // (4.E27) with zeta0 = zeta4 = 1, summed in MFeval's order: ... + zeta4 - 1
      r.SHy = (P.PHY1 + P.PHY2 * dfz) * P.LHY + (Kyg0 * gs - SVyg) / (r.Kya + eps * tire_sign_nz(r.Kya));
      r.SHy = (r.SHy + 1.0) - 1.0;
    }
    r.SVy = Fz * (P.PVY1 + P.PVY2 * dfz) * P.LVY * LMUY + SVyg;  // (4.E29)
    if (st.low_speed) {
      r.SVy = r.SVy * st.red_smooth;
      r.SHy = r.SHy * st.red_smooth;
    }
    const S alphay = alpha_star + r.SHy;  // (4.E20)
    r.Cy = K(P.PCY1 * P.LCY);             // (4.E21)
    r.muy = (P.PDY1 + P.PDY2 * dfz) * (1.0 + P.PPY3 * dpi + P.PPY4 * sq(dpi)) * (1.0 - P.PDY3 * sq(gs)) * LMUY;  // (4.E23)
    const S Dy = r.muy * Fz;  // (4.E22)
    S Ey = (P.PEY1 + P.PEY2 * dfz) * (1.0 + P.PEY5 * sq(gs) - (P.PEY3 + P.PEY4 * gs) * tire_sign_nz(alphay)) * P.LEY;  // (4.E24)
    if (options.limits && val(Ey) > 1) Ey = K(1.0);
    r.By = r.Kya / (r.Cy * Dy + eps * tire_sign_nz(Dy));  // (4.E26)
    const S Ba = r.By * alphay;
    r.Fy0 = Dy * sin_(r.Cy * atan_(Ba - Ey * (Ba - atan_(Ba)))) + r.SVy;  // (4.E19)
    if (val(Fz) == 0) r.muy = K(0.0);
    return r;
  };
  const mf_detail::MfLateral<S> lat = lateral(gamma_star);

  // ---- calculateMz0: the trail's and the residual moment's coefficients
  const S& Fzm = st.Fz_mz;
  const S SHt = P.QHZ1 + P.QHZ2 * dfz + (P.QHZ3 + P.QHZ4 * dfz) * gamma_star;  // (4.E35)
  const S Kya_prime = lat.Kya + eps * tire_sign_nz(lat.Kya);                  // (4.E39)
  const S SHf = lat.SHy + lat.SVy / Kya_prime;                                  // (4.E38)
  const S alphar = alpha_star + SHf;                                            // (4.E37)
  const S alphat = alpha_star + SHt;                                            // (4.E34)
  const S Dt = (P.QDZ1 + P.QDZ2 * dfz) * (1.0 - P.PPZ1 * dpi) * (1.0 + P.QDZ3 * gamma + P.QDZ4 * sq(gamma)) * Fzm *
               (R0 / Fz0p) * P.LTR;  // (A60)
  const S Bt = (P.QBZ1 + P.QBZ2 * dfz + P.QBZ3 * sq(dfz)) * (1.0 + P.QBZ4 * gamma + P.QBZ5 * abs_(gamma)) * P.LKY / LMUY;  // (A58)
  const double Ct = P.QCZ1;  // (4.E41)
  S Et = (P.QEZ1 + P.QEZ2 * dfz + P.QEZ3 * sq(dfz)) *
         (1.0 + (P.QEZ4 + P.QEZ5 * gamma_star) * (2.0 / pi) * atan_(Bt * Ct * alphat));  // (4.E44)
  if (options.limits && val(Et) > 1) Et = K(1.0);
  S Dr = Fzm * R0 *
         ((P.QDZ6 + P.QDZ7 * dfz) * P.LRES +
          ((P.QDZ8 + P.QDZ9 * dfz) * (1.0 + P.PPZ2 * dpi) + (P.QDZ10 + P.QDZ11 * dfz) * abs_(gamma_star)) * gamma_star *
              P.LKZC) *
         LMUY * tire_sign(Vcx) * cos_(alpha_star);  // (4.E47)
  Dr = (Dr + 1.0) - 1.0;                            // MFeval's + zeta8 - 1
  const S Br = P.QBZ9 * P.LKY / LMUY + P.QBZ10 * lat.By * lat.Cy;  // (4.E45)
  const double Cr = 1.0;                                          // (4.E46), zeta7 = 1

  // ---- calculateFx: combined slip
  S Fx;
  {
    const double Cxa = P.RCX1;  // (4.E55)
    S Exa = K(P.REX1) + P.REX2 * dfz;  // (4.E56)
    if (options.limits && val(Exa) > 1) Exa = K(1.0);
    const double SHxa = P.RHX1;  // (4.E57)
    const S Bxa = (P.RBX1 + P.RBX3 * sq(gamma_star)) * cos_(atan_(P.RBX2 * kappa)) * P.LXAL;  // (4.E54)
    const S alphas = alpha_star + SHxa;  // (4.E53)
    const S B0 = Bxa * SHxa;
    const S Gxa0 = cos_(Cxa * atan_(B0 - Exa * (B0 - atan_(B0))));  // (4.E52)
    const S B1 = Bxa * alphas;
    const S Gxa = cos_(Cxa * atan_(B1 - Exa * (B1 - atan_(B1)))) / Gxa0;  // (4.E51)
    Fx = Gxa * Fx0;                                                       // (4.E50)
  }

  // ---- calculateFy: combined slip (Gyk depends on the camber only through gamma_star, which
  // MFeval keeps at its true value also where it asks for Fy0 at zero camber)
  const double Cyk = P.RCY1;                  // (4.E63)
  const S SHyk = K(P.RHY1) + P.RHY2 * dfz;    // (4.E65)
  S Eyk = K(P.REY1) + P.REY2 * dfz;           // (4.E64)
  if (options.limits && val(Eyk) > 1) Eyk = K(1.0);
  const S Byk = (P.RBY1 + P.RBY4 * sq(gamma_star)) * cos_(atan_(P.RBY2 * (alpha_star - P.RBY3))) * P.LYKA;  // (4.E62)
  const S kappas = kappa + SHyk;  // (4.E61)
  S Gyk;
  {
    const S B0 = Byk * SHyk;
    const S Gyk0 = cos_(Cyk * atan_(B0 - Eyk * (B0 - atan_(B0))));  // (4.E60)
    const S B1 = Byk * kappas;
    Gyk = cos_(Cyk * atan_(B1 - Eyk * (B1 - atan_(B1)))) / Gyk0;  // (4.E59)
  }
  auto SVyk_of = [&](const S& muy) -> S {
    const S DVyk = muy * Fz * (P.RVY1 + P.RVY2 * dfz + P.RVY3 * gamma_star) * cos_(atan_(P.RVY4 * alpha_star));  // (4.E67)
    S SVyk = DVyk * sin_(P.RVY5 * atan_(P.RVY6 * kappa)) * P.LVYKA;  // (4.E66)
    if (st.low_speed) SVyk = SVyk * st.red_smooth;
    return SVyk;
  };
  const S Fy = Gyk * lat.Fy0 + SVyk_of(lat.muy);  // (4.E58)

  // ---- calculateMx: the draft paper's (49), with MFeval's reduction below FZMIN
  S Mx;
  {
    S Fzx = Fz;
    if (val(Fz) < P.FZMIN) Fzx = Fz * sq(Fz / P.FZMIN);
    Mx = R0 * Fzx * P.LMX *
             (P.QSX1 * P.LVMX - P.QSX2 * gamma * (1.0 + P.PPMX1 * dpi) - P.QSX12 * gamma * abs_(gamma) +
              P.QSX3 * Fy / Fz0 +
              P.QSX4 * cos_(P.QSX5 * atan_(sq(P.QSX6 * Fzx / Fz0))) * sin_(P.QSX7 * gamma + P.QSX8 * atan_(P.QSX9 * Fy / Fz0)) +
              P.QSX10 * atan_(P.QSX11 * Fzx / Fz0) * gamma) +
         R0 * Fy * P.LMX * (P.QSX13 + P.QSX14 * abs_(gamma));
  }

  // ---- calculateMy: the paper's (A48) (MF 5.2: the MF-Tyre manual's), MFeval's low-speed logic
  S My;
  {
    S Fzu = st.uFz;
    if (val(Fzu) < P.FZMIN) Fzu = Fzu * (Fzu / P.FZMIN);
    const S vr = Vcx / V0;
    const S vr2 = vr * vr;
    if (mf52) {
      My = -R0 * Fzu * P.LMY * (P.QSY1 + P.QSY2 * (Fx / Fz0) + P.QSY3 * abs_(vr) + P.QSY4 * (vr2 * vr2));
    } else {
      const S base = P.QSY1 + P.QSY2 * (Fx / Fz0) + P.QSY3 * abs_(vr) + P.QSY4 * (vr2 * vr2) +
                     (P.QSY5 + P.QSY6 * (Fzu / Fz0)) * sq(gamma);
      const S fzr = Fzu / Fz0;
      const S pr = p / P.NOMPRES;
      const S load = val(fzr) > 0 ? S(pow(fzr, P.QSY7)) : K(std::pow(0.0, P.QSY7));
      My = -R0 * Fz0 * P.LMY * base * (load * S(pow(pr, P.QSY8)));
    }
    if (val(Vcx) < 0) My = -My;
    if (val(Vcx) == 0) {
      My = K(0.0);
    } else {
      const S high = P.VXLOW / abs_(Vcx) - 1.0;
      const S low = -1.0 - P.VXLOW - high;
      const S& k = st.ukappa;
      if (val(k) >= val(low) && val(k) <= val(high)) {
        const S reduction = (0.0 * (high - k) + (pi / 2) * (k + 1.0)) / (high + 1.0);
        My = My * sin_(reduction);
      }
      if (val(k) < val(low)) My = -My;
    }
  }

  // ---- calculateMz: combined slip
  S Mz, trail, Mzr;
  {
    const S kr = sq(Kxk / Kya_prime) * sq(kappa);
    // (A54), (A55): atan(sqrt(tan(a)^2 + (Kxk/Kya')^2 kappa^2)) sign(a); at kappa = 0 this is a
    // itself (and atan(tan(a)) keeps the derivative that the square root loses at a = 0)
    auto equivalent = [&](const S& a) -> S {
      const S ta = tan_(a);
      if (val(kr) == 0) return atan_(ta);
      const S r = sqrt(S(sq(ta) + kr));
      return S(atan_(r) * tire_sign(a));
    };
    const S alphar_eq = equivalent(alphar);
    const S alphat_eq = equivalent(alphat);
    const S s = R0 * (P.SSZ1 + P.SSZ2 * (Fy / Fz0) + (P.SSZ3 + P.SSZ4 * dfz) * gamma) * P.LS;  // (A56)
    Mzr = Dr * cos_(Cr * atan_(Br * alphar_eq));                                             // (4.E75)
    const mf_detail::MfLateral<S> lat0 = lateral(K(0.0));  // Fy0 at zero camber
    const S Fy_prime = Gyk * lat0.Fy0;                       // (4.E74)
    const S Ba = Bt * alphat_eq;
    trail = Dt * cos_(Ct * atan_(Ba - Et * (Ba - atan_(Ba)))) * st.cos_alpha_prime;  // (4.E73)
    trail = trail * P.LFZO;  // as TNO's and MFeval's
    if (st.low_speed) {
      trail = trail * st.red_smooth;
      Mzr = Mzr * st.red_smooth;
    }
    if (mf52) Mz = -trail * (Fy - SVyk_of(lat0.muy)) + Mzr + s * Fx;  // MF-Tyre 5.2 manual
    else Mz = -trail * Fy_prime + Mzr + s * Fx;                        // (4.E71), (4.E72)
  }

  // ---- calculateRe: MFeval's fixed-point iteration on the spin omega = (1 + kappa) Vx / Re
  S Re = K(R0 * 0.965), omega = K(0.0);
  {
    const S Cz = K(P.VERTICAL_STIFFNESS) * (1.0 + P.PFZ1 * dpi);  // pressure-corrected stiffness
    const S fz = st.uFz / Fz0;
    const S deflection = (Fz0 / Cz) * (P.DREFF * atan_(P.BREFF * fz) + P.FREFF * fz);
    S Re_old = K(R0);
    for (int it = 0; it < 200 && std::abs(val(Re_old) - val(Re)) > 1e-9; ++it) {
      Re_old = Re;
      omega = (st.ukappa * Vcx + Vcx) / Re;
      const S Romega = R0 * (P.Q_RE0 + P.Q_V1 * sq((omega * R0) / V0));
      Re = Romega - deflection;
    }
  }

  TireForces<S> out;
  out.Fx = Fx;
  out.Fy = ms * Fy;
  out.Fz = st.uFz;
  out.Mx = ms * Mx;
  out.My = My;
  out.Mz = ms * Mz;
  out.Kxk = Kxk;
  out.Kya = lat.Kya;
  out.Re = Re;
  out.mux = mux;
  out.muy = options.limits && val(lat.muy) < 0 ? S(-lat.muy) : lat.muy;
  out.trail = trail;
  out.Mzr = ms * Mzr;
  out.omega = omega;
  return out;
}

}  // namespace codyna
