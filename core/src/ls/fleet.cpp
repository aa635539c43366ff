#include "dynid/ls/fleet.hpp"

#include <SuiteSparseQR.hpp>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

#include "dynid/error.hpp"

namespace dynid::ls {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Long = SuiteSparse_long;

// ---- validation -------------------------------------------------------------------------

std::size_t column_of(const FleetMember& member, const std::string& name) {
  for (std::size_t j = 0; j < member.parameters.size(); ++j)
    if (member.parameters[j].name == name) return j;
  throw InputError("fleet: vehicle '" + member.vehicle + "' has no parameter '" + name + "'");
}

void validate_member(const FleetMember& member) {
  if (member.vehicle.empty()) throw InputError("fleet: a vehicle id is empty");
  const auto width = static_cast<std::size_t>(member.groups.group(0).parameter_count());
  if (member.parameters.size() != width)
    throw InputError("fleet: vehicle '" + member.vehicle + "' names " +
                     std::to_string(member.parameters.size()) + " parameters for " +
                     std::to_string(width) + " columns");
  std::set<std::string> names;
  for (const auto& p : member.parameters)
    if (p.name.empty() || !names.insert(p.name).second)
      throw InputError("fleet: vehicle '" + member.vehicle + "' has an empty or repeated parameter '" +
                       p.name + "'");
}

void validate(const std::vector<FleetMember>& members, const std::vector<std::string>& shared) {
  if (members.empty()) throw InputError("fleet: no vehicle");
  std::set<std::string> vehicles;
  for (const auto& m : members) {
    validate_member(m);
    if (!vehicles.insert(m.vehicle).second)
      throw InputError("fleet: vehicle '" + m.vehicle + "' appears twice");
  }
  std::set<std::string> seen;
  for (const auto& name : shared) {
    if (name.empty() || !seen.insert(name).second)
      throw InputError("fleet: shared parameter '" + name + "' is empty or repeated");
    const auto& unit = members.front().parameters[column_of(members.front(), name)].unit;
    for (const auto& m : members) {
      const auto& other = m.parameters[column_of(m, name)].unit;
      if (other != unit)
        throw InputError("fleet: shared parameter '" + name + "' is in '" + unit + "' for vehicle '" +
                         members.front().vehicle + "' but in '" + other + "' for vehicle '" +
                         m.vehicle + "'");
    }
  }
}

// ---- layout: member column -> fleet column -----------------------------------------------

// Fleet columns in solve order: every member's locals (member by member), then the shared ones.
// Locals first keeps R block-angular: eliminating a vehicle's locals touches its rows only.
struct Layout {
  std::vector<std::vector<Eigen::Index>> column;  // [member][member column] -> fleet column
  std::vector<FleetParameterEstimate> parameters;  // per fleet column (solve order)
  Eigen::Index shared_begin = 0;
};

Layout make_layout(const std::vector<FleetMember>& members, const std::vector<std::string>& shared) {
  Layout l;
  const std::set<std::string> shared_set(shared.begin(), shared.end());
  l.column.resize(members.size());
  for (std::size_t v = 0; v < members.size(); ++v) {
    l.column[v].assign(members[v].parameters.size(), -1);
    for (std::size_t j = 0; j < members[v].parameters.size(); ++j) {
      const auto& p = members[v].parameters[j];
      if (shared_set.count(p.name) != 0) continue;
      l.column[v][j] = static_cast<Eigen::Index>(l.parameters.size());
      l.parameters.push_back({members[v].vehicle, p.name, p.unit, kNaN, kNaN, ParameterStatus::kIdentified});
    }
  }
  l.shared_begin = static_cast<Eigen::Index>(l.parameters.size());
  for (const auto& name : shared) {
    const auto& first = members.front();
    l.parameters.push_back({"", name, first.parameters[column_of(first, name)].unit, kNaN, kNaN,
                            ParameterStatus::kIdentified});
    for (std::size_t v = 0; v < members.size(); ++v)
      l.column[v][column_of(members[v], name)] = static_cast<Eigen::Index>(l.parameters.size()) - 1;
  }
  return l;
}

// ---- per-vehicle weighting -----------------------------------------------------------------

struct Weighted {
  std::vector<WeightedEstimate> vehicle;  // DYCARO's weighted system of each member
  double effective_rows = 0.0;
  std::uint64_t rows = 0;
};

Weighted weigh(const std::vector<FleetMember>& members, const EstimateOptions& options) {
  Weighted w;
  for (const auto& m : members) {
    try {
      w.vehicle.push_back(m.groups.estimate(options));
    } catch (const InputError& e) {
      throw InputError("fleet: vehicle '" + m.vehicle + "': " + e.what());
    }
    w.effective_rows += w.vehicle.back().weighted.effective_row_count();
    w.rows += w.vehicle.back().weighted.row_count();
  }
  return w;
}

// ---- the sparse system ----------------------------------------------------------------------

// The stacked rows [R_v | z_v] as triplets over fleet columns (row of R_v i -> sparse row).
struct Stacked {
  std::vector<Eigen::Triplet<double, Long>> entries;
  Eigen::VectorXd rhs;
  Eigen::VectorXd column_norm;
};

Stacked stack(const Weighted& w, const Layout& l) {
  Stacked s;
  Long rows = 0;
  for (const auto& v : w.vehicle) rows += v.weighted.parameter_count();
  s.rhs = Eigen::VectorXd::Zero(rows);
  s.column_norm = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(l.parameters.size()));
  Long offset = 0;
  for (std::size_t v = 0; v < w.vehicle.size(); ++v) {
    const Eigen::MatrixXd r = w.vehicle[v].weighted.augmented_r();
    const Eigen::Index n = r.cols() - 1;
    for (Eigen::Index i = 0; i < n; ++i) {
      s.rhs(offset + i) = r(i, n);
      for (Eigen::Index j = i; j < n; ++j) {
        if (r(i, j) == 0.0) continue;
        const Eigen::Index c = l.column[v][static_cast<std::size_t>(j)];
        s.entries.emplace_back(offset + i, c, r(i, j));
        s.column_norm(c) += r(i, j) * r(i, j);
      }
    }
    offset += n;
  }
  s.column_norm = s.column_norm.cwiseSqrt();
  return s;
}

// CHOLMOD objects freed with their common block.
struct Cholmod {
  cholmod_common cc;
  Cholmod() { cholmod_l_start(&cc); }
  ~Cholmod() { cholmod_l_finish(&cc); }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;
};

struct SparseQr {
  Eigen::SparseMatrix<double, Eigen::ColMajor, Long> r;  // rank x kept, columns in E order
  std::vector<Long> permutation;                          // R column k is kept column E[k]
  Eigen::VectorXd c;                                      // (Q^T b)(0:rank)
  Long rank = 0;
};

// SuiteSparseQR of A (m x kept, unit-norm columns) with b, fixed column order, tolerance tau.
SparseQr factor(const Eigen::SparseMatrix<double, Eigen::ColMajor, Long>& a, const Eigen::VectorXd& b,
                double tau) {
  Cholmod cm;
  cholmod_sparse view{};
  view.nrow = static_cast<std::size_t>(a.rows());
  view.ncol = static_cast<std::size_t>(a.cols());
  view.nzmax = static_cast<std::size_t>(a.nonZeros());
  view.p = const_cast<Long*>(a.outerIndexPtr());
  view.i = const_cast<Long*>(a.innerIndexPtr());
  view.x = const_cast<double*>(a.valuePtr());
  view.stype = 0;
  view.itype = CHOLMOD_LONG;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  cholmod_dense rhs{};
  rhs.nrow = static_cast<std::size_t>(b.size());
  rhs.ncol = 1;
  rhs.nzmax = rhs.nrow;
  rhs.d = rhs.nrow;
  rhs.x = const_cast<double*>(b.data());
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;

  cholmod_dense* c = nullptr;
  cholmod_sparse* r = nullptr;
  Long* e = nullptr;
  const Long rank =
      SuiteSparseQR<double>(SPQR_ORDERING_FIXED, tau, 0, &view, &rhs, &c, &r, &e, &cm.cc);
  if (rank < 0 || c == nullptr || r == nullptr) {
    cholmod_l_free_dense(&c, &cm.cc);
    cholmod_l_free_sparse(&r, &cm.cc);
    throw std::runtime_error("fleet: SuiteSparseQR failed (status " + std::to_string(cm.cc.status) + ")");
  }
  SparseQr out;
  out.rank = rank;
  const auto cols = static_cast<Long>(r->ncol);
  out.permutation.resize(static_cast<std::size_t>(cols));
  for (Long k = 0; k < cols; ++k) out.permutation[static_cast<std::size_t>(k)] = e ? e[k] : k;
  out.r = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, Long>>(
      static_cast<Long>(r->nrow), cols, static_cast<const Long*>(r->p)[cols],
      static_cast<const Long*>(r->p), static_cast<const Long*>(r->i), static_cast<const double*>(r->x));
  out.c = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(c->x), rank);
  cholmod_l_free_dense(&c, &cm.cc);
  cholmod_l_free_sparse(&r, &cm.cc);
  cm.cc.status = CHOLMOD_OK;
  if (e != nullptr) cholmod_l_free(static_cast<std::size_t>(cols), sizeof(Long), e, &cm.cc);
  return out;
}

// diag((R11^T R11)^-1): one sparse forward solve R11^T u = e_i per column, ||u||^2.
Eigen::VectorXd inverse_gram_diagonal(const Eigen::SparseMatrix<double, Eigen::ColMajor, Long>& r11) {
  const Eigen::SparseMatrix<double, Eigen::ColMajor, Long> rt = r11.transpose();
  Eigen::VectorXd d(r11.cols());
  Eigen::VectorXd u(r11.cols());
  for (Eigen::Index i = 0; i < r11.cols(); ++i) {
    u.setZero();
    u(i) = 1.0;
    rt.triangularView<Eigen::Lower>().solveInPlace(u);
    d(i) = u.squaredNorm();
  }
  return d;
}

// ---- assembling the answer -------------------------------------------------------------------

Eigen::VectorXd member_values(const Layout& l, std::size_t v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(l.column[v].size()));
  for (std::size_t j = 0; j < l.column[v].size(); ++j) {
    const double value = l.parameters[static_cast<std::size_t>(l.column[v][j])].value;
    x(static_cast<Eigen::Index>(j)) = std::isnan(value) ? 0.0 : value;  // as estimate.hpp
  }
  return x;
}

void residuals(const std::vector<FleetMember>& members, const Weighted& w, const Layout& l,
               FleetEstimate& out) {
  double weighted2 = 0.0;
  for (std::size_t v = 0; v < members.size(); ++v) {
    const Eigen::VectorXd x = member_values(l, v);
    const double rv = w.vehicle[v].weighted.residual_norm_at(x);
    weighted2 += rv * rv;
    FleetVehicleStatistics s{members[v].vehicle, 0, 0.0, w.vehicle[v].groups};
    double raw2 = 0.0;
    for (std::size_t g = 0; g < s.groups.size(); ++g) {
      if (s.groups[g].rows == 0) continue;
      const double rg = members[v].groups.group(g).residual_norm_at(x);
      s.groups[g].residual_rms = rg / std::sqrt(static_cast<double>(s.groups[g].rows));
      raw2 += rg * rg;
      s.rows += s.groups[g].rows;
    }
    s.residual_rms = std::sqrt(raw2 / static_cast<double>(s.rows));
    out.vehicles.push_back(std::move(s));
  }
  out.residual_norm = std::sqrt(weighted2);
}

}  // namespace

FleetEstimate fleet_estimate(const std::vector<FleetMember>& members,
                             const std::vector<std::string>& shared_parameter_names,
                             const EstimateOptions& options) {
  validate(members, shared_parameter_names);
  Layout layout = make_layout(members, shared_parameter_names);
  const Weighted weighted = weigh(members, options);
  const Stacked stacked = stack(weighted, layout);

  FleetEstimate out;
  out.rows = weighted.rows;
  out.sparse_rows = static_cast<std::uint64_t>(stacked.rhs.size());
  out.unknowns = static_cast<Eigen::Index>(layout.parameters.size());
  out.tolerance = weighted.effective_rows * options.base.epsilon;

  // Eliminated (not excited) columns are left out; the others are scaled to unit norm.
  const double largest = stacked.column_norm.maxCoeff();
  const double zero = std::max(options.base.zero_tolerance, out.tolerance) * largest;
  std::vector<Long> kept_of(layout.parameters.size(), -1);
  std::vector<Eigen::Index> kept;
  for (std::size_t c = 0; c < layout.parameters.size(); ++c) {
    if (stacked.column_norm(static_cast<Eigen::Index>(c)) <= zero) {
      layout.parameters[c].status = ParameterStatus::kEliminated;
      continue;
    }
    kept_of[c] = static_cast<Long>(kept.size());
    kept.push_back(static_cast<Eigen::Index>(c));
  }
  std::vector<Eigen::Triplet<double, Long>> entries;
  for (const auto& t : stacked.entries) {
    const Long k = kept_of[static_cast<std::size_t>(t.col())];
    if (k >= 0) entries.emplace_back(t.row(), k, t.value() / stacked.column_norm(t.col()));
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, Long> a(stacked.rhs.size(),
                                                       static_cast<Long>(kept.size()));
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();

  if (!kept.empty()) {
    const SparseQr qr = factor(a, stacked.rhs, out.tolerance);
    out.rank = static_cast<Eigen::Index>(qr.rank);
    const Eigen::SparseMatrix<double, Eigen::ColMajor, Long> r11 =
        qr.r.topLeftCorner(qr.rank, qr.rank);
    const Eigen::VectorXd xs = r11.triangularView<Eigen::Upper>().solve(qr.c);
    const Eigen::VectorXd gram = inverse_gram_diagonal(r11);
    // Every kept column past the rank is dependent; its value stays NaN.
    for (std::size_t k = static_cast<std::size_t>(qr.rank); k < qr.permutation.size(); ++k)
      layout.parameters[static_cast<std::size_t>(kept[static_cast<std::size_t>(qr.permutation[k])])]
          .status = ParameterStatus::kDependent;
    for (Long k = 0; k < qr.rank; ++k) {
      const auto c = kept[static_cast<std::size_t>(qr.permutation[static_cast<std::size_t>(k)])];
      auto& p = layout.parameters[static_cast<std::size_t>(c)];
      p.value = xs(k) / stacked.column_norm(c);
      p.standard_deviation = std::sqrt(gram(k)) / stacked.column_norm(c);  // times sigma below
    }
  }
  residuals(members, weighted, layout, out);
  out.degrees_of_freedom = weighted.effective_rows - static_cast<double>(out.rank);
  out.sigma = out.degrees_of_freedom > 0 ? out.residual_norm / std::sqrt(out.degrees_of_freedom) : kNaN;
  for (auto& p : layout.parameters) p.standard_deviation *= out.sigma;

  // Report order: shared first, then each member's locals.
  const auto shared_begin = layout.parameters.begin() + layout.shared_begin;
  out.parameters.assign(shared_begin, layout.parameters.end());
  out.parameters.insert(out.parameters.end(), layout.parameters.begin(), shared_begin);
  return out;
}

}  // namespace dynid::ls
