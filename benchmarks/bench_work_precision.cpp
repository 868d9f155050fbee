// Benchmark: work against precision. For each scene group (bench_scenes.hpp) sweep rtol
// over decades (atol = rtol / 100) and record the error against a reference, the time
// and the machine-independent counters (steps, residual and Jacobian evaluations,
// linear-solver setups).
//
// Error: max over the checkpoints (every 1/8 revolution or period, the end time
// included) and over the measured world positions of |p - p_ref| / L, L the model's
// characteristic length (printed per group). Reference: the closed form where there is
// one (rigid slider-crank, pendulum), else the engine's own nodal model at --ref-rtol
// (default 1e-13, or the tightest decade at which IDA runs it), whose convergence is
// shown by the differences between successive tolerances. Reduced (modal) models are compared with the nodal reference: their error
// levels off at the model error.
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "benchmarks/bench_common.hpp"
#include "benchmarks/bench_scenes.hpp"

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {

struct Reference {
  std::string source;  // "closed form" or "engine nodal rtol X"
  double rtol = 0;     // of an engine reference
  std::vector<double> times;
  std::vector<std::vector<double>> positions;
  std::vector<double> deflection;  // elastic models only
};

/// Reference cache: lines "group,ref_rtol,k,t,deflection,p0,p1,...".
using Cache = std::map<std::string, Reference>;
std::string cacheKey(const std::string& group, double rtol) { return group + "|" + fmt(rtol, "%.3g"); }

Cache readCache(const std::string& path) {
  Cache c;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("group,", 0) == 0) continue;
    std::stringstream ss(line);
    std::string group, item;
    std::getline(ss, group, ',');
    std::vector<double> v;
    while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
    if (v.size() < 4) continue;
    Reference& r = c[cacheKey(group, v[0])];
    r.source = "engine nodal rtol " + fmt(v[0], "%.0e") + " (cached in " + path + ")";
    r.times.push_back(v[2]);
    r.deflection.push_back(v[3]);
    r.positions.emplace_back(v.begin() + 4, v.end());
  }
  return c;
}

void writeCache(const std::string& path, const Cache& c) {
  std::ofstream out(path);
  out << "group,ref_rtol,k,t,deflection,positions...\n";
  for (const auto& [key, r] : c) {
    const std::string group = key.substr(0, key.find('|'));
    const std::string rtol = key.substr(key.find('|') + 1);
    for (std::size_t k = 0; k < r.times.size(); ++k) {
      out << group << "," << rtol << "," << k << "," << fmt(r.times[k], "%.17g") << ","
          << fmt(r.deflection[k], "%.17g");
      for (double p : r.positions[k]) out << "," << fmt(p, "%.17g");
      out << "\n";
    }
  }
}

double deflectionError(const std::vector<Probe>& run, const Reference& ref) {
  if (ref.deflection.empty() || std::isnan(ref.deflection[0]) || run.size() != ref.deflection.size()) return NAN;
  double peak = 0, e = 0;
  for (std::size_t k = 1; k < run.size(); ++k) {
    peak = std::max(peak, std::abs(ref.deflection[k]));
    e = std::max(e, std::abs(run[k].deflection - ref.deflection[k]));
  }
  return e / peak;
}

/// Largest relative change of energy and momenta over the outputs (conservative models).
std::pair<double, double> invariantDrift(const std::vector<Probe>& run) {
  double dE = NAN, dP = NAN;
  if (!run.empty() && !std::isnan(run[0].energy)) {
    dE = 0;
    for (const Probe& p : run) dE = std::max(dE, std::abs(p.energy - run[0].energy) / std::abs(run[0].energy));
  }
  if (!run.empty() && !std::isnan(run[0].angularMomentum)) {
    dP = 0;
    for (const Probe& p : run) {
      dP = std::max(dP, (p.momentum - run[0].momentum).norm() / run[0].momentum.norm());
      dP = std::max(dP, std::abs(p.angularMomentum - run[0].angularMomentum) / std::abs(run[0].angularMomentum));
    }
  }
  return {dE, dP};
}

struct Row {
  std::string group, model;
  double rtol = 0, seconds = 0, err = NAN, errDefl = NAN, diffNext = NAN, drE = NAN, drP = NAN;
  long steps = 0, res = 0, jac = 0, setups = 0;
  int size = 0;
  bool ok = true;
  std::vector<Probe> probes;
};

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_work_precision",
              "Work-precision sweep: error against a reference vs CPU time and solver counters, per scene.", 3);
  std::vector<std::string> scenes;
  double minRtol = 1e-11, maxRtol = 1e-3, refRtol = 1e-13, repeatLimit = 2.0;
  std::string refCache, integratorName = "ida";
  opt.addString("--integrator", "integrator of the sweep: ida, radau5 (default ida; references always IDA)",
                &integratorName);
  opt.addList("--scene", "scene groups to run: rigid_slider_crank, elastic_1rev, elastic_5rev, free_beam, "
              "pendulum (default: all)", &scenes);
  opt.addDouble("--min-rtol", "tightest rtol of the sweep (default 1e-11)", &minRtol);
  opt.addDouble("--max-rtol", "loosest rtol of the sweep (default 1e-3)", &maxRtol);
  opt.addDouble("--ref-rtol", "rtol of engine references (default 1e-13; atol = rtol/100)", &refRtol);
  opt.addDouble("--repeat-limit", "runs longer than this [s] are timed once, not --repeat times (default 2)",
                &repeatLimit);
  opt.addString("--ref-cache", "reuse engine references from this CSV file; missing ones are computed and "
                "added (default: none, references always recomputed)", &refCache);
  opt.parse(argc, argv);
  IntegratorKind integrator = IntegratorKind::Ida;
  try {
    integrator = parseIntegrator(integratorName);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_work_precision: %s\n", e.what());
    return 2;
  }
  if (opt.quick) {
    if (scenes.empty()) scenes = {"rigid_slider_crank", "pendulum", "free_beam", "elastic_1rev"};
    minRtol = std::max(minRtol, 1e-6);
    maxRtol = std::min(maxRtol, 1e-3);
    refRtol = std::max(refRtol, 1e-8);
    opt.repeat = 1;
  }
  std::vector<double> rtols;
  for (int e = -1; e >= -16; --e) {
    const double r = std::pow(10.0, e);
    if (r <= maxRtol * (1 + 1e-9) && r >= minRtol * (1 - 1e-9)) rtols.push_back(r);
  }
  std::vector<BenchModel> models;
  std::set<std::string> groups;
  for (BenchModel& m : allModels()) {
    if (!scenes.empty() && std::find(scenes.begin(), scenes.end(), m.group) == scenes.end()) continue;
    // the quick run keeps the elastic slider-crank to its cheap reduced models
    if (opt.quick && m.group == "elastic_1rev" && m.modes == 0) m.model = "nodal (reference only)";
    groups.insert(m.group);
    models.push_back(std::move(m));
  }
  for (const std::string& s : scenes) {
    if (!groups.count(s)) {
      std::fprintf(stderr, "bench_work_precision: unknown scene '%s'\n", s.c_str());
      return 2;
    }
  }

  Cache cache;
  if (!refCache.empty()) cache = readCache(refCache);
  bool cacheChanged = false;
  CsvWriter csv(opt.csvPath("bench_work_precision.csv"),
                {"group", "model", "rtol", "atol", "error", "error_deflection", "diff_next_rtol", "seconds", "steps",
                 "residual_evals", "jacobian_evals", "linear_setups", "dae_size", "ok", "energy_drift",
                 "momentum_drift", "reference"});
  std::printf("Work-precision sweep, integrator %s, atol = rtol/100, GGL, default linear solver (auto: KLU above 8 "
              "unknowns).\n", integratorName.c_str());
  std::printf(
              "error: max over checkpoints (end time included) and positions of |p - p_ref| / L; time: median of "
              "up to %d runs (one if a run takes > %.3g s), simulate() wall time incl. initialisation.\n",
              opt.repeat, repeatLimit);
  const auto wall0 = Clock::now();
  std::map<std::string, Reference> refs;
  std::string currentGroup;
  std::vector<Row> rows;
  for (const BenchModel& m : models) {
    if (m.group != currentGroup) {
      currentGroup = m.group;
      std::printf("\n== %s: %g s, %d checkpoints; positions: %s\n", m.group.c_str(), m.span, m.checkpoints,
                  m.positionsDoc.c_str());
      Reference ref;
      if (m.exact) {
        ref.source = "closed form";
        for (int k = 0; k <= m.checkpoints; ++k) {
          const double t = m.span * k / m.checkpoints;
          ref.times.push_back(t);
          ref.positions.push_back(m.exact(t));
          ref.deflection.push_back(NAN);
        }
      } else {
        // the first model of an engine-referenced group is its nodal model; if IDA cannot
        // run it at --ref-rtol (the nodal elastic slider-crank fails at t = 0 below rtol
        // 1e-10), the reference is the tightest decade that runs
        for (double rt = refRtol; rt <= 1e-6 * (1 + 1e-9); rt *= 10) {
          const std::string key = cacheKey(m.group, rt);
          if (cache.count(key) && cache[key].times.size() == static_cast<std::size_t>(m.checkpoints + 1)) {
            ref = cache[key];
            ref.rtol = rt;
            break;
          }
          Scene s = m.build(rt, atolFor(rt));
          s.solver.maxSteps = 100000000;
          const RunResult r = runModel(m, s);
          if (!r.summary.ok) {
            std::printf("reference run at rtol %.0e failed: %s\n", rt, r.summary.message.c_str());
            continue;
          }
          ref.source = "engine " + m.model + " rtol " + fmt(rt, "%.0e");
          ref.rtol = rt;
          ref.times = r.times;
          for (const Probe& p : r.probes) {
            ref.positions.push_back(p.positions);
            ref.deflection.push_back(p.deflection);
          }
          std::printf("reference run (%s): %ld steps, %.2f s\n", ref.source.c_str(), r.summary.stats.steps,
                      r.seconds);
          if (!refCache.empty()) {
            cache[key] = ref;
            cacheChanged = true;
          }
          break;
        }
        if (ref.times.empty()) {
          std::fprintf(stderr, "no reference for %s\n", m.group.c_str());
          return 1;
        }
      }
      std::printf("reference: %s\n", ref.source.c_str());
      std::printf("%-22s %7s %9s %9s %9s %10s %9s %8s %8s %7s %7s %9s %9s\n", "model", "rtol", "error", "err defl",
                  "diff next", "time [s]", "t/t_nodal", "steps", "res", "jac", "setups", "dE", "dP");
      refs[m.group] = ref;
    }
    const Reference& ref = refs[m.group];
    const std::size_t first = rows.size();
    for (double rtol : rtols) {
      if (m.model == "nodal (reference only)") break;
      if (m.modes == 0 && rtol <= ref.rtol * (1 + 1e-9)) break;  // the reference model at or below its rtol
      Row row;
      row.group = m.group;
      row.model = m.model;
      row.rtol = rtol;
      std::vector<double> times;
      for (int rep = 0; rep < opt.repeat; ++rep) {
        Scene s = m.build(rtol, atolFor(rtol));
        s.solver.maxSteps = 100000000;
        s.solver.integrator = integrator;
        RunResult r = runModel(m, s);
        times.push_back(r.seconds);
        row.ok = r.summary.ok;
        row.steps = r.summary.stats.steps;
        row.res = r.summary.stats.residualEvals;
        row.jac = r.summary.stats.jacobianEvals;
        row.setups = r.summary.stats.linearSetups;
        row.size = r.size;
        row.probes = std::move(r.probes);
        if (!row.ok) std::fprintf(stderr, "%s %s rtol %g failed: %s\n", m.group.c_str(), m.model.c_str(), rtol,
                                  r.summary.message.c_str());
        if (r.seconds > repeatLimit) break;
      }
      row.seconds = median(times);
      row.err = row.ok ? positionError(m, row.probes, ref.positions) : NAN;
      row.errDefl = row.ok ? deflectionError(row.probes, ref) : NAN;
      std::tie(row.drE, row.drP) = invariantDrift(row.probes);
      rows.push_back(std::move(row));
    }
    // differences between successive tolerances (convergence of the model itself)
    for (std::size_t i = first; i + 1 < rows.size(); ++i) {
      std::vector<std::vector<double>> next;
      for (const Probe& p : rows[i + 1].probes) next.push_back(p.positions);
      rows[i].diffNext = positionError(m, rows[i].probes, next);
    }
    for (std::size_t i = first; i < rows.size(); ++i) {
      Row& r = rows[i];
      double tNodal = NAN;
      for (const Row& o : rows) {
        if (o.group == r.group && o.model == "nodal" && o.rtol == r.rtol) tNodal = o.seconds;
      }
      std::printf("%-22s %7.0e %9s %9s %9s %10.4f %9s %8ld %8ld %7ld %7ld %9s %9s%s\n", r.model.c_str(), r.rtol,
                  sci(r.err).c_str(), sci(r.errDefl).c_str(), sci(r.diffNext).c_str(), r.seconds,
                  std::isnan(tNodal) ? "-" : fmt(r.seconds / tNodal, "%.3f").c_str(), r.steps, r.res, r.jac, r.setups,
                  sci(r.drE).c_str(), sci(r.drP).c_str(), r.ok ? "" : "  FAILED");
      csv.row({r.group, r.model, fmt(r.rtol, "%.0e"), fmt(atolFor(r.rtol), "%.0e"), fmt(r.err, "%.6e"),
               fmt(r.errDefl, "%.6e"), fmt(r.diffNext, "%.6e"), fmt(r.seconds, "%.6g"), std::to_string(r.steps),
               std::to_string(r.res), std::to_string(r.jac), std::to_string(r.setups), std::to_string(r.size),
               r.ok ? "1" : "0", fmt(r.drE, "%.3e"), fmt(r.drP, "%.3e"), ref.source});
      r.probes.clear();
      r.probes.shrink_to_fit();
    }
  }
  if (cacheChanged) {
    writeCache(refCache, cache);
    std::printf("\nreferences cached in %s\n", refCache.c_str());
  }
  std::printf("\nerror: position error vs the reference / L; err defl: rod midpoint deflection error / its peak "
              "(elastic);\ndiff next: the same position measure between this rtol and the next tighter one (the "
              "convergence of the model itself);\ndE, dP: largest relative change of energy and of the momenta "
              "(free beam) over the outputs.\n");
  std::printf("total wall time %.1f s; CSV written to %s\n", secondsSince(wall0), csv.path().c_str());
  return 0;
}
