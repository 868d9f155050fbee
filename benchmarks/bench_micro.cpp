// Micro-benchmarks (Google Benchmark): one residual evaluation, one Jacobian assembly
// (into a JacobianSink::sparse of the DAE's pattern, as the integrators use it, with the
// scratch of one integrator) and one KLU refactorisation (klu_l_analyze and klu_l_factor
// once, then klu_l_refactor on the pattern's CSC arrays), at the consistent initial
// state, cj = 1e6 (about 1/h of the runs at rtol 1e-6), for these models:
//   crank<N>     the elastic slider-crank (GGL) with N nodal rod elements (--elements)
//   bari_ggl     Simeon's crank of the Bari test set (examples/bari_slider_crank.json), GGL
//   bari_index1  the same, index 1
//   bari_hand    the test set's hand-coded equations (problems/bari_crank.hpp)
//   rigid_crank  the rigid slider-crank (examples/slider_crank_rigid.json), GGL
// After the runs: the cost of a Jacobian and of a refactorisation in residual evaluations
// (target: a Jacobian costs at most a few residuals).
//
// Options of its own (--elements, --quick, --repeat, --csv, --out-dir, --loop); any other
// argument goes to Google Benchmark (--benchmark_filter=..., ...). --loop MODEL:KIND:N
// (KIND residual or jacobian) only makes N evaluations of one model and exits, for
// instruction counts under callgrind (benchmarks/compare_builds.py --callgrind).
#include <benchmark/benchmark.h>
#include <klu.h>

#include "integrators/klu_ordering.hpp"

#include <unistd.h>

#include <cstdio>
#include <map>
#include <memory>

#include "benchmarks/bench_common.hpp"
#include "benchmarks/bench_scenes.hpp"
#include "problems/bari_crank.hpp"
#include "integrators/initial_conditions.hpp"

using namespace flexmbd;
using namespace flexmbd::bench;

namespace {

constexpr double kTime = 0.0, kCj = 1e6;

/// One model's DAE at its consistent initial state, built once per model.
struct Fixture {
  Scene scene;
  std::unique_ptr<DaeProblem> dae;
  std::unique_ptr<DaeScratch> scratch;
  VecX y, yp, F;
  std::vector<double> values;
  std::vector<SuiteSparse_long> colStart, rowIndex;
};

/// "crank<N>", "bari_ggl", "bari_index1", "bari_hand" or "rigid_crank".
Fixture& fixture(const std::string& model) {
  static std::map<std::string, std::unique_ptr<Fixture>> all;
  auto& f = all[model];
  if (!f) {
    f = std::make_unique<Fixture>();
    if (model == "bari_hand") {
      f->dae = std::make_unique<bari::HandCodedCrank>();
      bari::HandCodedCrank::initialValues(f->y, f->yp);
    } else {
      const bool bari = model.rfind("bari", 0) == 0;
      if (model == "rigid_crank") {
        f->scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_rigid.json");
      } else {
        f->scene = bari ? loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/bari_slider_crank.json")
                        : testmodels::elasticSliderCrank(std::stoi(model.substr(5)), 1.0, 0, 1.0, 1e-6, 1e-8);
      }
      const System& sys = f->scene.system;
      const ConsistentState cs = computeConsistentState(sys, kTime, sys.initialCoordinates(), sys.initialVelocities());
      auto dae = std::make_unique<DaeSystem>(sys, model == "bari_index1" ? Formulation::Index1 : Formulation::Ggl);
      dae->packState(cs.q, cs.v, cs.a, cs.lambda, f->y, f->yp);
      f->dae = std::move(dae);
    }
    f->scratch = f->dae->makeScratch();
    f->F.resize(f->dae->size());
    const SparsePattern& p = f->dae->pattern();
    f->values.assign(p.nonZeros(), 0.0);
    f->colStart.assign(p.colStart().begin(), p.colStart().end());
    f->rowIndex.assign(p.rowIndex().begin(), p.rowIndex().end());
  }
  return *f;
}

void residual(Fixture& f) { f.dae->residual(kTime, f.y.data(), f.yp.data(), f.F.data(), *f.scratch); }

void sizeCounters(benchmark::State& st, const Fixture& f) {
  st.counters["dae_size"] = f.dae->size();
  st.counters["nnz"] = static_cast<double>(f.dae->pattern().nonZeros());
}

void assembleJacobian(Fixture& f) {
  std::fill(f.values.begin(), f.values.end(), 0.0);
  JacobianSink sink = JacobianSink::sparse(f.values.data(), f.dae->pattern());
  f.dae->jacobian(kTime, f.y.data(), f.yp.data(), kCj, sink, *f.scratch);
}

void residualBench(benchmark::State& st, const std::string& model) {
  Fixture& f = fixture(model);
  for (auto _ : st) {
    residual(f);
    benchmark::DoNotOptimize(f.F.data());
    benchmark::ClobberMemory();
  }
  sizeCounters(st, f);
}

void jacobianBench(benchmark::State& st, const std::string& model) {
  Fixture& f = fixture(model);
  // a residual's cost measured alongside, for the ratio counter
  const double tRes = timePerCall([&] { residual(f); }, std::max(1, 20000 / f.dae->size()), 5);
  const auto t0 = Clock::now();
  for (auto _ : st) {
    assembleJacobian(f);
    benchmark::DoNotOptimize(f.values.data());
    benchmark::ClobberMemory();
  }
  const double tJac = secondsSince(t0) / static_cast<double>(st.iterations());
  sizeCounters(st, f);
  st.counters["jac_in_residuals"] = tJac / tRes;
}

/// engineOrdering: as the engine's IdaSolver (KluOrdering::choose); else KLU's
/// defaults (AMD after BTF, pivot threshold 1e-3), for comparison.
void kluRefactorBench(benchmark::State& st, const std::string& model, bool engineOrdering) {
  Fixture& f = fixture(model);
  assembleJacobian(f);
  klu_l_common common;
  klu_l_defaults(&common);
  const KluOrdering ordering =
      engineOrdering ? KluOrdering::choose(*f.dae, 0.0, f.y, f.yp, kOrderingTrialCj) : KluOrdering();
  ordering.configure(common);
  const SuiteSparse_long n = f.dae->size();
  klu_l_symbolic* sym = klu_l_analyze(n, f.colStart.data(), f.rowIndex.data(), &common);
  klu_l_numeric* num = sym ? klu_l_factor(f.colStart.data(), f.rowIndex.data(), f.values.data(), sym, &common)
                           : nullptr;
  if (!num) {
    st.SkipWithError("KLU analyze/factor failed");
    if (sym) klu_l_free_symbolic(&sym, &common);
    return;
  }
  for (auto _ : st) {
    const int ok = klu_l_refactor(f.colStart.data(), f.rowIndex.data(), f.values.data(), sym, num, &common);
    benchmark::DoNotOptimize(ok);
  }
  sizeCounters(st, f);
  st.counters["lu_nnz"] = static_cast<double>(num->lnz + num->unz);
  klu_l_free_numeric(&num, &common);
  klu_l_free_symbolic(&sym, &common);
}

/// Console output as usual; the per-iteration times kept for the ratios.
class CollectingReporter : public benchmark::ConsoleReporter {
 public:
  CollectingReporter() : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_ColorTabular : OO_Tabular) {}
  std::map<std::string, double> seconds;  // benchmark name -> real time per iteration [s]
  std::map<std::string, double> iterations;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred) continue;
      // plain runs, or the median aggregate when repeated
      const bool use = r.run_type == Run::RT_Iteration ? !r.report_big_o && r.repetitions <= 1
                                                       : r.aggregate_name == "median";
      if (!use) continue;
      const std::string name = r.run_name.function_name;
      seconds[name] = r.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(r.time_unit);
      iterations[name] = static_cast<double>(r.iterations);
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace

int main(int argc, char** argv) {
  Options opt("bench_micro", "Residual, Jacobian and KLU refactorisation of the elastic slider-crank and the Bari crank (Google Benchmark).",
              1);
  std::vector<std::string> elementList;
  opt.addList("--elements", "rod meshes (default 8,256; --quick: 8,32)", &elementList);
  std::string loop;
  opt.addString("--loop", "MODEL:KIND:N: N residual or jacobian evaluations of one model, no timing (callgrind)", &loop);
  std::vector<std::string> gbArgs;
  opt.parse(argc, argv, &gbArgs);
  if (!loop.empty()) {
    const size_t a = loop.find(':'), b = loop.rfind(':');
    if (a == std::string::npos || b == a) {
      std::fprintf(stderr, "bench_micro: --loop MODEL:KIND:N\n");
      return 2;
    }
    const std::string model = loop.substr(0, a), kind = loop.substr(a + 1, b - a - 1);
    const int n = Options::toInt(loop.substr(b + 1), "--loop");
    Fixture& f = fixture(model);
    for (int i = 0; i < n; ++i) {
      if (kind == "residual") {
        residual(f);
      } else {
        assembleJacobian(f);
      }
    }
    benchmark::DoNotOptimize(f.F.data());
    benchmark::DoNotOptimize(f.values.data());
    return 0;
  }
  if (elementList.empty()) elementList = opt.quick ? std::vector<std::string>{"8", "32"} : std::vector<std::string>{"8", "256"};
  std::vector<std::string> models;
  for (const std::string& e : elementList) models.push_back("crank" + std::to_string(Options::toInt(e, "--elements")));
  for (const char* m : {"bari_ggl", "bari_index1", "bari_hand", "rigid_crank"}) models.push_back(m);

  std::vector<std::string> args = {argv[0]};
  if (opt.quick) args.push_back("--benchmark_min_time=0.02");
  if (opt.repeat > 1) {
    args.push_back("--benchmark_repetitions=" + std::to_string(opt.repeat));
    args.push_back("--benchmark_report_aggregates_only=true");
  }
  args.insert(args.end(), gbArgs.begin(), gbArgs.end());
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  int cargc = static_cast<int>(cargs.size());
  benchmark::Initialize(&cargc, cargs.data());
  if (benchmark::ReportUnrecognizedArguments(cargc, cargs.data())) return 2;

  for (const std::string& m : models) {
    const std::string suffix = "/" + m;
    benchmark::RegisterBenchmark(("residual" + suffix).c_str(), residualBench, m)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("jacobian" + suffix).c_str(), jacobianBench, m)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("klu_refactor" + suffix).c_str(), kluRefactorBench, m, true)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("klu_refactor_default_ordering" + suffix).c_str(), kluRefactorBench, m, false)
        ->Unit(benchmark::kMicrosecond);
  }
  CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  CsvWriter csv(opt.csvPath("bench_micro.csv"),
                {"model", "dae_size", "jacobian_nonzeros", "residual_us", "jacobian_us", "klu_refactor_us",
                 "jacobian_in_residuals", "klu_refactor_in_residuals", "klu_refactor_default_ordering_us"});
  std::printf("\n%12s %8s %10s %12s %12s %14s %10s %10s %16s\n", "model", "size", "nnz(J)", "residual[us]",
              "jacobian[us]", "klu_refac[us]", "jac/res", "klu/res", "klu_default[us]");
  for (const std::string& m : models) {
    const std::string suffix = "/" + m;
    const auto get = [&](const std::string& name) {
      const auto it = reporter.seconds.find(name + suffix);
      return it == reporter.seconds.end() ? NAN : it->second;
    };
    const double tr = get("residual"), tj = get("jacobian"), tk = get("klu_refactor");
    const double tkd = get("klu_refactor_default_ordering");
    const Fixture& f = fixture(m);
    std::printf("%12s %8d %10lld %12.3f %12.3f %14.3f %10.2f %10.2f %16.3f\n", m.c_str(), f.dae->size(),
                static_cast<long long>(f.dae->pattern().nonZeros()), 1e6 * tr, 1e6 * tj, 1e6 * tk, tj / tr, tk / tr,
                1e6 * tkd);
    csv.row({m, std::to_string(f.dae->size()), std::to_string(f.dae->pattern().nonZeros()),
             fmt(1e6 * tr), fmt(1e6 * tj), fmt(1e6 * tk), fmt(tj / tr, "%.3f"), fmt(tk / tr, "%.3f"), fmt(1e6 * tkd)});
  }
  std::printf("jac/res, klu/res: the cost of one Jacobian assembly and of one KLU refactorisation in residual "
              "evaluations (target: a Jacobian costs at most a few residuals).\nCSV written to %s\n",
              csv.path().c_str());
  return 0;
}
