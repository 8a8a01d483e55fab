#include "model/data.hpp"

#include "spatial/autodiff.hpp"

namespace codyna {

template <class S>
DataT<S>::DataT(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.nbodies);
  liMi.resize(nb);
  oMi.resize(nb);
  Sb.assign(nb, Mat6xT<S>(6, 0));
  v.assign(nb, Vec6T<S>::Zero());
  cJ.assign(nb, Vec6T<S>::Zero());
  a.assign(nb, Vec6T<S>::Zero());
  f.assign(nb, Vec6T<S>::Zero());
  fext.assign(nb, Vec6T<S>::Zero());
  IA.assign(nb, Mat6T<S>::Zero());
  pA.assign(nb, Vec6T<S>::Zero());
  U.assign(nb, Mat6xT<S>(6, 0));
  Dinv.resize(nb);
  u.resize(nb);
  c.assign(nb, Vec6T<S>::Zero());
  Ic.assign(nb, Mat6T<S>::Zero());
  tau = VecXT<S>::Zero(model.nv);
  // M [nv x nv] is sized by crba() when a mass matrix is asked for: ABA and kinematics never need it
  nle = VecXT<S>::Zero(model.nv);
  Q = VecXT<S>::Zero(model.nv);
  qdd = VecXT<S>::Zero(model.nv);
  lambda = VecXT<S>::Zero(model.nc);
  phi = VecXT<S>::Zero(model.nc);
  Jc = MatXT<S>::Zero(model.nc, model.nv);
  gamma = VecXT<S>::Zero(model.nc);
}

template struct DataT<double>;
template struct DataT<ADScalar>;

}  // namespace codyna
