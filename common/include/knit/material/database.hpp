// The material database: the only contract between knit-meso and knit-macro.
//
// An HDF5 file (layout in schemas/database.layout.json and docs/database.md) holding, per
// loop length, the raw homogenized data of every load path and step (F*, P*, E, S, status),
// the fitted response surfaces of eq. (17) and the S12(E12) curve, and the fit diagnostics;
// globally the loop lengths, the yarn and cell parameters, the sweep input, the strain
// domain covered by the data, the format version and the provenance.
//
// Writing (the sweep, `knit-meso synth`, `knit-meso fit`): fill a Database, then
// write_database(path, db) (atomic: temporary file, then rename). Reading:
// read_database(path) validates the layout and throws knit::InputError naming the file and
// the HDF5 path of what is wrong (another format version, a truncated file, a missing group).
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "knit/material/energy_law.hpp"
#include "knit/material/load_paths.hpp"
#include "knit/material/loop_length_family.hpp"
#include "knit/material/response_surface.hpp"
#include "knit/material/uniaxial_curve.hpp"

namespace knit::io {
class H5File;  // knit/io/hdf5.hpp
}  // namespace knit::io

namespace knit::material {

/// Version 2 adds the energy-based law (/energy_law); version 3 its "family" attribute and the
/// network family (version 2 laws are ridge laws). Versions 1 and 2 still load.
inline constexpr int kDatabaseFormatVersion = 3;
inline constexpr const char* kDatabaseFormatName = "knitscale-material-database";
/// Largest |F|, |E| (dimensionless) and |P|, |S| (MPa) of a raw step a database may hold: no
/// state of a textile cell lies beyond (session 29: 1e308 made the paper fit's rms inf).
inline constexpr double kMaxRawKinematic = 1e3;
inline constexpr double kMaxRawStress = 1e9;

using RowMatrixX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Homogenized results of one load path, one row per load step k = 1..steps (the undeformed
/// state k = 0 is implicit: F = I, P = 0). Row layouts:
///   F, P: (F11, F12, F21, F22) -- P* of eq. (8), MPa
///   E:    (E11, E22, E12)      -- tensor components (not Voigt 2E12)
///   S:    (S11, S22, S12)      -- MPa
/// status: 0 = converged, anything else = the step did not converge (the fit skips it).
struct RawPath {
  LoadPath path;
  RowMatrixX F, P, E, S;
  std::vector<int> status;
  /// Its number among its loop length's paths (/loop_<k>/raw/path_<index>, two digits at
  /// least), so that a message about a path in a filtered list names it in the file; -1 when
  /// not known.
  int index = -1;
  int steps() const { return static_cast<int>(status.size()); }
};

/// Unit-cell parameters of one loop length (paper Sect. 3.1.1), mm.
struct CellParameters {
  double wale_width = 0.0;     ///< w
  double course_height = 0.0;  ///< c
  double thickness = 0.0;      ///< t = 2d
};

/// RMS and max error of a fit per component (E1, E2, S1, S2, S12): E1, E2 are the
/// E-surface's distance to the data strains; S1, S2, S12 are the law's stress errors
/// |S_fit(E_data) - S_data| (MPa).
struct FitDiagnostics {
  static constexpr int kComponents = 5;
  static constexpr const char* kNames[kComponents] = {"E1", "E2", "S1", "S2", "S12"};
  Eigen::Matrix<double, kComponents, 1> rms = Eigen::Matrix<double, kComponents, 1>::Zero();
  Eigen::Matrix<double, kComponents, 1> max = Eigen::Matrix<double, kComponents, 1>::Zero();
  /// Largest stress error relative to the data's stress range (max |S| over all components).
  double max_relative = 0.0;
  /// The largest of the stress components' RMS errors relative to the same range (not stored
  /// in the database; the fit's refusal reads it).
  double rms_relative = 0.0;
  int points_used = 0, points_skipped = 0;
  std::string options_json;  ///< the fit options used (JSON text)
};

struct LoopLengthEntry {
  double loop_length = 0.0;  ///< l, mm
  CellParameters cell;
  std::vector<RawPath> raw;
  std::optional<ResponseSurfaceData> surface;  ///< absent until fitted
  FitDiagnostics diagnostics;
};

/// The strain domain covered by the data (min/max over all converged steps).
struct StrainDomain {
  double E11_min = 0, E11_max = 0, E22_min = 0, E22_max = 0, E12_max = 0;
};

/// Errors of the energy-based law (issue 11): per loop length on the fit data, and on the
/// held-out paths (set "holdout", never fitted). Components S11, S22, S12 (MPa). The stress
/// range of a loop length is the largest (max - min) of a stress component over its fit data;
/// relative errors divide by it (held-out states by the range of their loop length).
struct EnergyFitDiagnostics {
  struct PerLoop {
    double loop_length = 0.0;
    int points = 0;
    Eigen::Vector3d rms = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();
    double stress_range = 0.0, max_relative = 0.0, rms_relative = 0.0;
    /// The data's own floor for a convex law (fraction of stress_range): the largest
    /// -(S_i - S_j) . (e_i - e_j) / (2 range |e_i - e_j|_1) over pairs of the loop length's
    /// states, fitted and held out, and the stress-free origin. A convex W has a monotone
    /// gradient, so it misses one state of such a pair by at least that much. NaN when unknown
    /// (files written before session 10).
    double monotonicity_bound = std::nan("");
    /// The law driven like the cell's uniaxial-stress paths (axial strain prescribed, lateral
    /// strain solved so that the law's lateral stress vanishes): law / cell axial stress at
    /// the last converged step, course (0) and wale (1); NaN without such a path. Printed, not
    /// stored.
    Eigen::Vector2d uniaxial_end_ratio = Eigen::Vector2d::Constant(std::nan(""));
    /// Largest |law / cell - 1| of that axial stress over the steps whose cell stress is at
    /// least 10 % of the path's largest, both axes. Printed, not stored.
    double uniaxial_max_relative = 0.0;
    /// Those paths step by step, course (0) and wale (1): the cell's axial strain and stress
    /// and the law's own axial stress (uniaxial_curve.hpp); empty without such a path. Stored
    /// in /energy_law/diagnostics/uniaxial (session 41; absent from older files).
    std::array<UniaxialCurve, 2> uniaxial;
  };
  std::vector<PerLoop> per_loop;
  int holdout_points = 0;
  int holdout_within_5_percent = 0;  ///< held-out states whose largest error is <= 5 % of the range
  Eigen::Vector3d holdout_rms = Eigen::Vector3d::Zero(), holdout_max = Eigen::Vector3d::Zero();
  double holdout_max_relative = 0.0;
  /// Held-out cell runs (paths of set "holdout", each to one quasi-random state of the box):
  /// how many, how many are within 5 % of the range at every converged step, and how many at
  /// their last converged step (the run's target state). Printed, not stored.
  int holdout_runs = 0, holdout_runs_within_5_percent = 0, holdout_run_ends_within_5_percent = 0;
  int points_used = 0, points_skipped = 0;
  double min_eigenvalue = 0.0;  ///< smallest eigenvalue of C over the fit data (>= floor)
  std::string options_json;
};

struct Provenance {
  std::string software_version, git_revision, created;  ///< created: ISO 8601 UTC
  /// The file the database was made from, as given (the sweep's input, the database a fit
  /// read; "" for synth): the root attribute `input` (session 37: it was "" for every file).
  std::string input;
  /// When the file was written: the root attribute `date_utc` (io::write_provenance; "" for a
  /// file without it). Read only: a writer stamps its own time. knit-macro run keeps it in
  /// results.h5, so that the report tells results of another database (session 38).
  std::string date_utc;
};

struct Database {
  int format_version = kDatabaseFormatVersion;
  Provenance provenance;
  std::string generator;    ///< "sweep", "synth" (synthetic stand-in), ...
  std::string sweep_input;  ///< the sweep's input (JSON text)
  /// /sweep/report@failed_cases when the file has it (read only): above 0, the sweep that
  /// wrote this database failed, and wrote it for the diagnosis (knit-meso sweep, exit 1).
  int sweep_failed_cases = 0;
  /// Read only: false for a file written before the checksums (issue 14; format versions 1-2),
  /// whose contents the reader cannot verify. Such a file is read, and said so by its users.
  bool checksummed = true;
  std::map<std::string, double> yarn;    ///< e.g. diameter, youngs_modulus, poisson_ratio
  std::vector<LoopLengthEntry> entries;  ///< increasing loop length
  /// The energy-based law (format version 2, /energy_law); absent in version-1 files and
  /// until `knit-meso fit --law energy|both` has run.
  std::optional<EnergyLawData> energy_law;
  EnergyFitDiagnostics energy_diagnostics;

  std::vector<double> loop_lengths() const;
  StrainDomain domain() const;
  /// The loop-length family of the fitted laws; throws std::invalid_argument if any entry is
  /// not fitted.
  LoopLengthFamily family() const;
};

/// The energy law of db, read from `file`; throws knit::InputError(file, "/energy_law", ...)
/// saying how to add it when db has none (a version-1 file, or a database fitted without it).
const EnergyLawData& require_energy_law(const Database& db, const std::string& file);

/// HDF5 path of raw path q of loop length k ("/loop_k/raw/path_qq"), for messages.
std::string raw_path_location(std::size_t k, std::size_t q);

/// The first converged step (status 0) of db's raw data that the reader would refuse: a
/// non-finite F, P, E or S, or a value beyond kMaxRawKinematic (F, E) or kMaxRawStress (P, S),
/// as "/loop_k/raw/path_qq/S: step s is not finite" or "... holds |value| 1.2e9 (F, E at most
/// 1e3; P, S at most 1e9 MPa)"; nothing if there is none. The writer refuses to write such a
/// database (session 21: `knit-meso synth --loop-lengths 1e-300` wrote inf and NaN stresses
/// with exit 0; session 38: `--loop-lengths 0.0001` wrote 1.4e9 MPa, which the reader refused).
std::optional<std::string> first_unstorable_step(const Database& db);

/// Provenance of this build, now.
Provenance current_provenance();

/// Writes atomically (temporary file next to `file`, then rename). Throws std::runtime_error,
/// and writes nothing, when a converged step cannot be stored (first_unstorable_step). `extra`,
/// when given, adds to the open file before it is closed and renamed (the sweep's
/// /sweep/report; `knit-meso fit` copies the input's objects the Database does not hold), so
/// one temporary and one rename make the whole file (session 26: the sweep wrote the database
/// into its own temporary, a nested "..DB.h5.tmp-P-n.tmp-P-m" that a kill left for good).
void write_database(const std::filesystem::path& file, const Database& db,
                    const std::function<void(io::H5File&)>& extra = {});

/// Copies into `to` (a database being written) every object of `from` (the database it was
/// made from) at the root or directly under /sweep that `to` does not hold: what a Database
/// does not carry, such as the sweep's /sweep/report and groups a user added. Marks a copied
/// /sweep/report (attribute "refitted") as describing the sweep's own fit. Returns the copied
/// paths. Session 26: `knit-meso fit` dropped /sweep/report, with exit 0.
std::vector<std::string> carry_over_unwritten(const io::H5File& from, io::H5File& to,
                                              const std::string& refit_note);

/// What `from` holds that `to` does not, after carry_over_unwritten: HDF5 paths of objects
/// ("/loop_0/user_ds") and attributes ("/loop_0@note") anywhere but inside the groups the refit
/// rewrote (/energy_law when `energy_refit`, each /loop_<k>/fit when `paper_refit`: an earlier
/// fit's items there are replaced by design). knit-meso fit refuses an in-place refit that would
/// drop such items (session 41's red team: a file without checksums lost a user's attributes
/// and datasets inside /loop_0 with exit 0).
std::vector<std::string> items_not_carried(const io::H5File& from, const io::H5File& to,
                                           bool energy_refit, bool paper_refit);

/// The error of a database write into the temporary `temp` of `target` that failed with `e`
/// (a full file system, say): "TARGET: database not written (the earlier file is left as it
/// was | no file was created): REASON", REASON without the temporary's name (gone by then) or
/// an inner "database not written" of a nested write. `existed`: whether `target` existed.
std::runtime_error database_not_written(const std::filesystem::path& target, bool existed,
                                        const std::filesystem::path& temp, const std::exception& e);

/// Refuses to let a synthetic stand-in (`knit-meso synth`, a sweep with the synthetic runner)
/// replace a database swept on the unit cell (root attribute generator "sweep"): throws
/// knit::InputError(file, "/@generator", ...) naming `option`. Nothing when `file` is absent,
/// not HDF5 or holds another generator. Session 50's red team: synth wrote over a swept
/// database in place, exit 0, and the cases ran on the stand-in (41.3 N for 154.7 N).
void refuse_replacing_swept_database(const std::filesystem::path& file, const std::string& option);

/// Reads and validates. Throws knit::InputError(file, hdf5_path, what) on a bad file.
/// raw = false skips the raw path data (faster for the macroscale).
Database read_database(const std::filesystem::path& file, bool raw = true);

}  // namespace knit::material
