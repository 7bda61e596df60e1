// A rod problem read from a JSON case file (schema: schemas/rod.schema.json) and its run:
//   knit-meso rod CASE.json [-o OUTDIR]
// Outputs in OUTDIR (built as OUTDIR.partial-<pid>, then renamed: never half-written):
//   load_displacement.csv   step, lambda, Newton iterations, then <point>_ux,_uy,_uz [mm] for
//                           every named output point (displacement from the reference)
//   centerline_NNNN.vtp     sampled centerlines per converged step (radius, force, moment, d1)
//   centerline.pvd          ParaView collection over the load factor
// Bad input: knit::InputError with the JSON pointer of the offending field (exit code 2),
// nothing written.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "knit/meso/rod/resolution.hpp"
#include "knit/meso/rod/rod_system.hpp"
#include "knit/meso/rod/solver.hpp"

namespace knit::meso::rod {

struct NamedPoint {
  std::string name;
  int rod = 0;
  double xi = 1.0;
};

struct RodCase {
  std::string file;
  std::string description;
  RodSystem system;
  PathOptions path;
  std::vector<NamedPoint> points;
  int samples_per_element = 8;
  bool write_vtp = true;
  /// /output/check_resolution: solve again on the bisected mesh and compare (resolution.hpp)
  bool check_resolution = true;
};

/// The path report plus the resolution check (absent when not run: disabled, or the path
/// stopped early).
struct CasePathReport : PathReport {
  std::optional<ResolutionCheck> resolution;
  /// False when no load step completed (none of the path's target steps; cut-back
  /// sub-increments may have converged short of the first): nothing was written, and an earlier
  /// output in the directory is left as it was (session 41's red team: it was replaced by the
  /// reference state alone; knit-meso path and knit-macro run do the same).
  bool written = true;
  /// Where the completed earlier output of the directory went when this stopped run replaced
  /// it (DIR.last-completed; io::AtomicDirectory::set_completed), else empty.
  std::filesystem::path earlier_kept_in;
};

/// The full load's scaled residual at the reference state must exceed the Newton tolerance by
/// this factor, or the case is refused at /steps/tolerance (the loads would not be resolved).
inline constexpr double kLoadResolution = 1e3;

/// The largest turn of a prescribed end rotation in one load step, rad (choice: a third of a
/// turn). An end rotation is reached as exp(lambda theta), a rotation, which is the same for
/// theta and theta minus a full turn along it: a step that turns an end by pi or more is
/// solved the shorter way round (session 50's red team: 4 rad in one step gave the arc of
/// -2.28 rad, curled the other way, and 2 pi in one step no deformation at all, exit 0). At a
/// third of a turn the other way round is twice as long, far from the tie at pi; the case is
/// refused at /steps/count, with the count that keeps each step within it.
inline constexpr double kMaxStepRotation = 2.0 * 3.14159265358979323846 / 3.0;
/// /steps/tolerance's minimum, a double's round-off (schemas/rod.schema.json).
inline constexpr double kMinRodTolerance = 2.2e-16;
/// /steps/count's maximum (schemas/rod.schema.json).
inline constexpr double kMaxRodSteps = 1e6;

/// The estimated size of a case's outputs in bytes: one VTP per load step and the start (about
/// 200 bytes per sampled centerline point), and the CSV.
std::uint64_t estimate_output_bytes(const RodCase& c);
/// The default cap on it (knit-meso rod --max-output-size), as knit-macro run's: 2 GB.
inline constexpr std::uint64_t kDefaultMaxOutputBytes = 2'000'000'000;
/// Throws knit::InputError(file, "/steps/count", ...) if the estimate exceeds max_bytes (0: no
/// cap). Session 29 (a helper's fuzzing audit): 1e6 steps, which the schema allows, would
/// write 1e6 VTP files, about 12 GB, with no word before.
void check_output_size(const RodCase& c, std::uint64_t max_bytes);

/// Reads and checks a case file; throws knit::InputError(file, pointer, message).
RodCase load_rod_case(const std::filesystem::path& file);

/// Solves the case along its load path and writes the outputs into outdir (atomically, also
/// when the path stops early: then the outputs hold the converged steps). Progress lines go
/// to `log` if given.
CasePathReport run_rod_case(const RodCase& c, const std::filesystem::path& outdir,
                            std::ostream* log = nullptr);

}  // namespace knit::meso::rod
