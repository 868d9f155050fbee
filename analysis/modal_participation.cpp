#include "analysis/modal_participation.hpp"

#include <algorithm>
#include <sstream>

namespace flexmbd {

ModalParticipation::ModalParticipation(const System& sys) : modes_(elasticModes(sys)) {
  int largest = 0;
  for (const BodyModes& m : modes_) {
    shapeSize_.push_back(m.shapes.cwiseAbs().colwise().maxCoeff().transpose());
    maxEta_.push_back(VecX::Zero(m.size()));
    maxEnergy_.push_back(VecX::Zero(m.size()));
    largest = std::max(largest, m.size());
  }
  eta_ = VecX::Zero(largest);
  etaDot_ = VecX::Zero(largest);
}

void ModalParticipation::add(const VecX& q, const VecX& v) {
  for (size_t b = 0; b < modes_.size(); ++b) {
    const BodyModes& m = modes_[b];
    const int nf = m.size();
    eta_.head(nf).noalias() = m.projector * q.segment(m.coordinateOffset, nf);  // eta = Phi^T M q_f (GeradinRixen)
    etaDot_.head(nf).noalias() = m.projector * v.segment(m.velocityOffset, nf);
    for (int k = 0; k < nf; ++k) {
      maxEta_[b][k] = std::max(maxEta_[b][k], std::abs(eta_[k]));
      // kinetic + strain energy of the mode (mass-normalised): (eta'^2 + omega^2 eta^2) / 2
      const double e = 0.5 * (etaDot_[k] * etaDot_[k] + m.omega[k] * m.omega[k] * eta_[k] * eta_[k]);
      maxEnergy_[b][k] = std::max(maxEnergy_[b][k], e);
    }
  }
}

std::vector<BodyParticipation> ModalParticipation::result() const {
  std::vector<BodyParticipation> out;
  for (size_t b = 0; b < modes_.size(); ++b) {
    const BodyModes& m = modes_[b];
    BodyParticipation p;
    p.body = m.name;
    p.nodal = m.nodal;
    const double total = maxEnergy_[b].sum();
    for (int k = 0; k < m.size(); ++k) {
      p.modes.push_back({m.omega[k], maxEta_[b][k] * shapeSize_[b][k], maxEnergy_[b][k]});
      if (total > 0.0 && maxEnergy_[b][k] >= kCarryingEnergyFraction * total) p.carrying.push_back(k + 1);
    }
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<std::string> ModalParticipation::warnings() const {
  std::vector<std::string> out;
  for (const BodyParticipation& p : result()) {
    if (!p.nodal || p.carrying.empty() || p.modes.empty()) continue;
    const double fastestCarrying = p.modes[p.carrying.back() - 1].omega, fastest = p.modes.back().omega;
    const bool few = static_cast<double>(p.carrying.size()) <= kReducibleCoordinateFraction * p.modes.size();
    if (!few || fastest < kReducibleFrequencyRatio * fastestCarrying) continue;
    std::ostringstream os;
    os.precision(3);
    os << "body '" << p.body << "' (nodal, " << p.modes.size() << " elastic coordinates) moved in modes";
    for (int k : p.carrying) os << ' ' << k;
    os << " (up to " << fastestCarrying << " rad/s; each above " << kCarryingEnergyFraction
       << " of the peak elastic energy): a model reduced to them (\"modes\": [...]) would resolve modes up to "
       << fastestCarrying << " rad/s instead of " << fastest << ", much cheaper (summary.json modal_participation)";
    out.push_back(os.str());
  }
  return out;
}

}  // namespace flexmbd
