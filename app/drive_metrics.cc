#include "app/drive_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <sstream>

#include "models/errors.h"
#include "models/text_format.h"

namespace linetrack::app {
namespace {

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream split(line);
  for (std::string field; std::getline(split, field, ',');)
    out.push_back(field);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

std::optional<double> OptionalNumber(const std::string& field, const std::string& where) {
  if (field.empty()) return std::nullopt;
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(field, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != field.size() || !std::isfinite(value)) {
    throw InputError(where + ": '" + field + "' is not a finite number");
  }
  return value;
}

std::string Percent(int part, int whole) {
  return whole > 0 ? Fixed(100.0 * part / whole, 1) + " %" : "n/a";
}

// The source of a pose carried by the odometry (SequenceTracker's coasting).
constexpr const char* kCoastedSource = "odometry";

bool Beyond(const ReplayedFrame& f, double metres, double degrees) {
  return f.translation_error_m.value_or(0.0) > metres ||
         f.rotation_error_deg.value_or(0.0) > degrees;
}

// The blackouts of a drive: runs of covered frames, as [first, last] frame numbers.
std::vector<std::pair<long, long>> CoveredRuns(const std::vector<FrameTruth>& truth) {
  std::vector<std::pair<long, long>> runs;
  for (size_t k = 0; k < truth.size(); ++k) {
    if (!truth[k].covered) continue;
    if (k > 0 && truth[k - 1].covered) {
      runs.back().second = truth[k].frame;
    } else {
      runs.emplace_back(truth[k].frame, truth[k].frame);
    }
  }
  return runs;
}

std::string RecoveryText(const DriveMetrics& m) {
  if (m.recoveries.empty()) return "no blackout";
  std::string out;
  for (const BlackoutRecovery& r : m.recoveries) {
    if (!out.empty()) out += ", ";
    out += r.frames_to_recover >= 0 ? std::to_string(r.frames_to_recover) : "never";
  }
  return out;
}

std::string KidnapText(const DriveMetrics& m) {
  if (m.kidnaps.empty()) return "no kidnap";
  std::string out;
  int wrong = 0;
  for (const KidnapRecovery& k : m.kidnaps) {
    if (!out.empty()) out += ", ";
    out += k.frames_to_recover >= 0 ? std::to_string(k.frames_to_recover) : "never";
    wrong += k.wrong_tracking;
  }
  return out + " (" + std::to_string(wrong) + " wrong `tracking` poses meanwhile)";
}

}  // namespace

std::vector<ReplayedFrame> ParseReplayFrames(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  std::string line;
  std::map<std::string, size_t> column;
  std::vector<ReplayedFrame> out;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::string where = source + ":" + std::to_string(number);
    const std::vector<std::string> fields = SplitCsv(line);
    if (column.empty()) {
      for (size_t i = 0; i < fields.size(); ++i)
        column[fields[i]] = i;
      for (const char* name : {"frame", "time", "status", "time_ms", "translation_error_m",
                               "rotation_error_deg", "note"}) {
        if (column.count(name) == 0) {
          throw InputError(where + ": no '" + std::string(name) +
                           "' column (a replay's frames.csv with ground truth is expected)");
        }
      }
      continue;
    }
    // The note is last and may hold anything but commas; it takes the remaining fields.
    if (fields.size() < column["note"]) throw InputError(where + ": too few fields");
    auto field = [&](const char* name) { return fields[column[name]]; };
    ReplayedFrame f;
    f.frame = std::lround(OptionalNumber(field("frame"), where).value_or(-1.0));
    f.t = OptionalNumber(field("time"), where).value_or(0.0);
    f.status = field("status");
    if (column.count("source")) f.source = field("source");
    f.step_ms = OptionalNumber(field("time_ms"), where).value_or(0.0);
    f.translation_error_m = OptionalNumber(field("translation_error_m"), where);
    f.rotation_error_deg = OptionalNumber(field("rotation_error_deg"), where);
    f.has_pose = f.translation_error_m.has_value();
    if (column["note"] < fields.size()) f.note = fields[column["note"]];
    out.push_back(f);
  }
  if (column.empty()) throw InputError(source + ": empty frames file");
  return out;
}

bool DriveMetricsOptions::Check(std::string* why) const {
  if (!(near_m > 0.0 && near_m <= far_m) || !(near_deg > 0.0 && near_deg <= far_deg) || worst < 0) {
    *why = "bounds must be positive with near <= far, and the worst-frame count >= 0";
    return false;
  }
  return true;
}

double DriveMetrics::Availability() const {
  return observable > 0 ? static_cast<double>(observable_with_pose) / observable : 0.0;
}

double DriveMetrics::TrackingAvailability() const {
  return observable > 0 ? static_cast<double>(observable_tracking) / observable : 0.0;
}

DriveMetrics ComputeDriveMetrics(const std::vector<FrameTruth>& truth,
                                 const std::vector<ReplayedFrame>& replayed, double overall_fps,
                                 const DriveMetricsOptions& options) {
  DriveMetrics m;
  m.overall_fps = overall_fps;
  std::map<long, const FrameTruth*> truth_of;
  for (const FrameTruth& t : truth)
    truth_of[t.frame] = &t;
  std::map<long, const ReplayedFrame*> replay_of;
  double squares = 0.0, tracking_ms = 0.0;
  int tracking_frames = 0;
  for (size_t i = 0; i < replayed.size(); ++i) {
    const ReplayedFrame& f = replayed[i];
    const auto it = truth_of.find(f.frame);
    if (it == truth_of.end()) continue;
    replay_of[f.frame] = &f;
    ++m.frames;
    const bool observable = it->second->observable;
    const bool tracking = f.status == "tracking";
    m.observable += observable;
    if (tracking) {
      ++tracking_frames;
      tracking_ms += f.step_ms;
    }
    if (!f.has_pose) continue;
    ++m.poses;
    m.observable_with_pose += observable;
    m.observable_tracking += observable && tracking;
    m.observable_tracking_coasted += observable && tracking && f.source == kCoastedSource;
    m.poses_unobservable += !observable;
    m.beyond_near += Beyond(f, options.near_m, options.near_deg);
    m.tracking_beyond_near += f.status == "tracking" && Beyond(f, options.near_m, options.near_deg);
    m.beyond_far += Beyond(f, options.far_m, options.far_deg);
    const double e = f.translation_error_m.value_or(0.0), r = f.rotation_error_deg.value_or(0.0);
    squares += e * e;
    if (e > m.worst_m) m.worst_m = e, m.worst_m_frame = f.frame;
    if (r > m.worst_deg) m.worst_deg = r, m.worst_deg_frame = f.frame;
    m.worst_frames.push_back(i);
  }
  m.ate_m = m.poses > 0 ? std::sqrt(squares / m.poses) : 0.0;
  m.tracking_fps = tracking_ms > 0.0 ? 1000.0 * tracking_frames / tracking_ms : 0.0;
  std::sort(m.worst_frames.begin(), m.worst_frames.end(), [&](size_t a, size_t b) {
    return replayed[a].translation_error_m.value_or(0.0) >
           replayed[b].translation_error_m.value_or(0.0);
  });
  if (m.worst_frames.size() > static_cast<size_t>(options.worst))
    m.worst_frames.resize(options.worst);

  for (const auto& [first, last] : CoveredRuns(truth)) {
    BlackoutRecovery r;
    r.first = first;
    r.last = last;
    for (const FrameTruth& t : truth) {
      if (t.frame <= last) continue;
      if (r.first_observable < 0 && t.observable) r.first_observable = t.frame;
      if (r.first_observable < 0) continue;
      const auto it = replay_of.find(t.frame);
      if (it != replay_of.end() && it->second->has_pose && it->second->source != kCoastedSource &&
          !Beyond(*it->second, options.near_m, options.near_deg)) {
        r.recovered = t.frame;
        r.frames_to_recover = static_cast<int>(t.frame - r.first_observable);
        break;
      }
    }
    m.recoveries.push_back(r);
  }
  return m;
}

std::string FormatDriveTable(const std::vector<DriveReport>& reports,
                             const DriveMetricsOptions& options) {
  std::vector<std::pair<std::string, std::vector<std::string>>> rows;
  auto row = [&](const std::string& label, auto cell) {
    std::vector<std::string> cells;
    for (const DriveReport& r : reports)
      cells.push_back(cell(r.metrics, r));
    rows.emplace_back(label, cells);
  };
  const std::string near =
      Fixed(100.0 * options.near_m, 0) + " cm / " + Fixed(options.near_deg, 0) + " deg";
  const std::string far =
      Fixed(100.0 * options.far_m, 0) + " cm / " + Fixed(options.far_deg, 0) + " deg";
  row("frames (observable)", [](const DriveMetrics& m, const DriveReport&) {
    return std::to_string(m.frames) + " (" + std::to_string(m.observable) + ")";
  });
  row("availability: observable frames with a pose", [](const DriveMetrics& m, const auto&) {
    return Percent(m.observable_with_pose, m.observable);
  });
  row("availability: observable frames with a `tracking` pose",
      [](const DriveMetrics& m, const auto&) {
        return Percent(m.observable_tracking, m.observable);
      });
  row("... of which coasted on the odometry (no image fix)",
      [](const DriveMetrics& m, const auto&) {
        return Percent(m.observable_tracking_coasted, m.observable);
      });
  row("poses beyond " + near, [](const DriveMetrics& m, const auto&) {
    return std::to_string(m.beyond_near) + " of " + std::to_string(m.poses);
  });
  row("`tracking` poses beyond " + near,
      [](const DriveMetrics& m, const auto&) { return std::to_string(m.tracking_beyond_near); });
  row("poses beyond " + far,
      [](const DriveMetrics& m, const auto&) { return std::to_string(m.beyond_far); });
  row("poses on unobservable frames",
      [](const DriveMetrics& m, const auto&) { return std::to_string(m.poses_unobservable); });
  row("ATE (camera centre RMSE)",
      [](const DriveMetrics& m, const auto&) { return Fixed(100.0 * m.ate_m, 2) + " cm"; });
  row("worst error: position (frame) / rotation (frame)", [](const DriveMetrics& m, const auto&) {
    return Fixed(100.0 * m.worst_m, 1) + " cm (" + std::to_string(m.worst_m_frame) + ") / " +
           Fixed(m.worst_deg, 2) + " deg (" + std::to_string(m.worst_deg_frame) + ")";
  });
  row("frames to recover after each blackout",
      [](const DriveMetrics& m, const auto&) { return RecoveryText(m); });
  row("frames to recover after each kidnap (to a `tracking` pose)",
      [](const DriveMetrics& m, const auto&) { return KidnapText(m); });
  row("replay fps: tracking frames / overall", [](const DriveMetrics& m, const auto&) {
    return Fixed(m.tracking_fps, 0) + " / " + Fixed(m.overall_fps, 0);
  });
  row("odometry drift (largest over 10 m)",
      [](const DriveMetrics&, const DriveReport& r) { return Fixed(r.drift_percent, 2) + " %"; });
  // The integrity monitor's figures (replay's summary.json, "integrity").
  row("integrity failures (`tracking` beyond its protection level)",
      [](const DriveMetrics& m, const auto&) {
        return m.integrity_failures ? std::to_string(*m.integrity_failures) : "n/a";
      });
  row("covariance calibration: NEES within its chi-square 99 % quantile",
      [](const DriveMetrics& m, const auto&) {
        return m.nees_within_99 ? Fixed(100.0 * *m.nees_within_99, 1) + " %" : "n/a";
      });
  row("NEES (x, y, heading) within chi2(3) 50 / 90 / 99 / 99.9 %; mean (3)",
      [](const DriveMetrics& m, const auto&) -> std::string {
        if (!m.nees_within_99) return "n/a";
        std::string text;
        for (double share : m.nees_shares)
          text += (text.empty() ? "" : " / ") + Fixed(100.0 * share, 1);
        return text + " %; " + Fixed(m.mean_nees, 2);
      });
  row("median sigma / median error (position)", [](const DriveMetrics& m, const auto&) {
    return m.nees_within_99 ? Fixed(100.0 * m.median_sigma_m, 2) + " / " +
                                  Fixed(100.0 * m.median_error_m, 2) + " cm"
                            : "n/a";
  });
  row("protection level (position) p50 / p90", [](const DriveMetrics& m, const auto&) {
    return m.nees_within_99 ? Fixed(100.0 * m.protection_p50_m, 1) + " / " +
                                  Fixed(100.0 * m.protection_p90_m, 1) + " cm"
                            : "n/a";
  });
  row("sigma x p50 / p90; sigma heading p50", [](const DriveMetrics& m, const auto&) {
    return m.nees_within_99
               ? Fixed(100.0 * m.sigma_x_p50_m, 2) + " / " + Fixed(100.0 * m.sigma_x_p90_m, 2) +
                     " cm; " + Fixed(m.sigma_heading_p50_deg, 3) + " deg"
               : "n/a";
  });

  std::string out = "| |";
  std::string rule = "| --- |";
  for (const DriveReport& r : reports) {
    out += " " + r.name + " |";
    rule += " --- |";
  }
  out += "\n" + rule + "\n";
  for (const auto& [label, cells] : rows) {
    out += "| " + label + " |";
    for (const std::string& c : cells)
      out += " " + c + " |";
    out += "\n";
  }
  return out;
}

void AddKidnapRecoveries(const std::vector<FrameTruth>& truth,
                         const std::vector<ReplayedFrame>& replayed,
                         const std::vector<long>& kidnap_frames, const DriveMetricsOptions& options,
                         DriveMetrics* m) {
  std::map<long, const ReplayedFrame*> replay_of;
  for (const ReplayedFrame& f : replayed)
    replay_of[f.frame] = &f;
  for (size_t k = 0; k < kidnap_frames.size(); ++k) {
    KidnapRecovery r;
    r.frame = kidnap_frames[k];
    const long next = k + 1 < kidnap_frames.size() ? kidnap_frames[k + 1] : -1;
    for (const FrameTruth& t : truth) {
      if (t.frame < r.frame) continue;
      if (next >= 0 && t.frame >= next) break;
      const auto it = replay_of.find(t.frame);
      const ReplayedFrame* f = it != replay_of.end() ? it->second : nullptr;
      const bool tracking = f && f->has_pose && f->status == "tracking";
      const bool near = tracking && !Beyond(*f, options.near_m, options.near_deg);
      r.wrong_tracking += tracking && !near;
      if (r.first_observable < 0 && t.observable) r.first_observable = t.frame;
      if (r.first_observable >= 0 && near) {
        r.recovered = t.frame;
        r.frames_to_recover = static_cast<int>(t.frame - r.first_observable);
        break;
      }
    }
    m->kidnaps.push_back(r);
  }
}

void AddIntegrityFigures(const nlohmann::json& integrity, DriveMetrics* m) {
  if (!integrity.is_object() || !integrity.contains("ground_truth")) return;
  const nlohmann::json& g = integrity["ground_truth"];
  m->integrity_failures = g.value("integrity_failures", 0);
  const nlohmann::json& regions = g["regions"];
  for (size_t i = 0; i < m->nees_shares.size() && i < regions.size(); ++i)
    m->nees_shares[i] = regions[i].value("share_inside", 0.0);
  m->nees_within_99 = m->nees_shares[2];
  m->mean_nees = g.value("mean_nees", 0.0);
  m->median_sigma_m = g.value("median_sigma_m", 0.0);
  m->median_error_m = g.value("median_error_m", 0.0);
  auto p = [&](const char* key, const char* q) {
    return integrity.contains(key) && integrity[key].is_object() ? integrity[key].value(q, 0.0)
                                                                 : 0.0;
  };
  m->sigma_x_p50_m = p("sigma_x_m", "p50");
  m->sigma_x_p90_m = p("sigma_x_m", "p90");
  m->sigma_heading_p50_deg = p("sigma_heading_deg", "p50");
  m->protection_p50_m = p("protection_level_m", "p50");
  m->protection_p90_m = p("protection_level_m", "p90");
}

std::string FormatWorstFrames(const DriveMetrics& metrics, const std::vector<FrameTruth>& truth,
                              const std::vector<ReplayedFrame>& replayed) {
  std::map<long, const FrameTruth*> truth_of;
  for (const FrameTruth& t : truth)
    truth_of[t.frame] = &t;
  std::string out =
      "| frame | t (s) | status | error | observable (edges) | people | gain | blur (px) | "
      "centre depth (m) | pan (deg) | note |\n"
      "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const size_t i : metrics.worst_frames) {
    const ReplayedFrame& f = replayed[i];
    const FrameTruth& t = *truth_of.at(f.frame);
    out += "| " + std::to_string(f.frame) + " | " + Fixed(f.t, 1) + " | " + f.status + " | " +
           Fixed(100.0 * f.translation_error_m.value_or(0.0), 1) + " cm / " +
           Fixed(f.rotation_error_deg.value_or(0.0), 2) + " deg | " +
           (t.observable ? "yes" : "no") + " (" + std::to_string(t.observable_edges) + ") | " +
           Fixed(100.0 * t.people_share, 0) + " % | " + Fixed(t.gain, 2) + " | " +
           Fixed(t.blur_px, 1) + " | " + Fixed(t.centre_depth_m, 2) + " | " + Fixed(t.pan_deg, 0) +
           " | " + f.note + " |\n";
  }
  return out;
}

}  // namespace linetrack::app
