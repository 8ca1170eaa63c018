#include "eval_report.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "output_folder.hpp"
#include "smx/plots/plots.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) {
    return "–";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
std::string pct(double ratio, int decimals = 1) {
  return std::isfinite(ratio) ? fixed(100.0 * ratio, decimals) + " %" : "–";
}
// A completeness over a region the frame hardly has (a sliver where a pattern ends) is no
// figure.
constexpr int kMinRegionPixels = 1000;
double ratioOrNaN(const eval::DepthScore& s, double ratio) {
  return s.regionPixels >= kMinRegionPixels ? ratio : kNaN;
}
std::string completeness(const eval::DepthScore& s) {
  return pct(ratioOrNaN(s, s.completeness));
}

// A usable result: most of the smooth lit surface measured, few gross errors.
constexpr double kUsableCompleteness = 0.90;
constexpr double kUsableGross = 0.01;
bool usable(const eval::FrameFigures& f) {
  return f.mergedSmooth.completeness >= kUsableCompleteness &&
         f.mergedAll.grossRate <= kUsableGross;
}

std::string slug(std::string s) {
  for (char& c : s) {
    if (std::isalnum(static_cast<unsigned char>(c)) == 0) {
      c = '_';
    }
  }
  return s;
}

struct Writer {
  OutputFolder& results;
  std::ostringstream md;
  std::string error;
  std::set<std::string> written;

  void plot(const std::string& name, const OutputFolder::Writer& write) {
    written.insert(name);
    if (auto ok = error.empty() ? results.write(name, write) : std::expected<void, std::string>{};
        !ok) {
      error = ok.error();
    }
  }
  void image(const std::string& alt, const std::string& name) {
    md << "![" << alt << "](results/" << name << ")\n";
  }

  // The default renders take the scenes' own 2 × 2 samples per pixel, which place a stripe edge
  // only to within half a pixel (docs/demux.md "Accuracy").
  static std::string samplingNote(const eval::Report& r) {
    if (r.supersampling == 0) {
      return "";
    }
    return ", " + std::to_string(r.supersampling) + " × " + std::to_string(r.supersampling) +
           " samples per pixel";
  }

  void scenes(const eval::Report& r) {
    if (r.scenes.empty()) {
      return;
    }
    md << "## Scenes\n\n"
          "Each named scene rendered by the simulator (the paper's noise, seed "
       << r.seed << samplingNote(r)
       << ") and decoded by the firmware's camera pipeline; the merged range image of all "
          "projectors, scored against the truth depth.\n\n"
          "| scene | rig | camera | completeness, all lit | smooth | lit by 2 | lit by 3 | gross "
          "| RMSE mm | RMSE disparity px |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& s : r.scenes) {
      const auto& f = s.figures;
      md << "| " << s.scene << " | " << s.rigFile << " | cam" << s.camera << " | "
         << completeness(f.mergedAll) << " | " << completeness(f.mergedSmooth) << " | "
         << completeness(f.merged2) << " | " << completeness(f.merged3) << " | "
         << pct(f.mergedAll.grossRate, 2) << " | " << fixed(f.mergedAll.rmseMm, 2) << " | "
         << fixed(f.mergedAll.rmsDisparityPx, 3) << " |\n";
    }
    md << "\n### Per projector–camera pair\n\n"
          "Each projector's own range image where it lights the surface (smooth interior), and "
          "where exactly 2 or 3 patterns light it.\n\n"
          "| scene | rig | pair | completeness, smooth | lit by 2 | lit by 3 | gross | RMSE mm "
          "| RMSE disparity px |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& s : r.scenes) {
      for (std::size_t p = 0; p < s.figures.pairs.size(); ++p) {
        const auto& d = s.figures.pairs[p];
        md << "| " << s.scene << " | " << s.rigFile << " | proj" << p << "–cam" << s.camera << " | "
           << completeness(d) << " | " << completeness(s.figures.pairs2[p]) << " | "
           << completeness(s.figures.pairs3[p]) << " | " << pct(d.grossRate, 2) << " | "
           << fixed(d.rmseMm, 2) << " | " << fixed(d.rmsDisparityPx, 3) << " |\n";
      }
    }
    plots::BarChart bars{"Completeness per scene (merged range image)",
                         "completeness",
                         0,
                         1,
                         {},
                         {"all lit pixels", "lit by 2 (smooth)", "lit by 3 (smooth)"},
                         {{}, {}, {}}};
    md << "\n";
    for (const auto& s : r.scenes) {
      const std::string label = s.scene +
                                (s.rigFile.find("3proj") != std::string::npos ? " 3p" : "") +
                                (s.camera > 0 || s.rigFile.find("2cam") != std::string::npos
                                     ? " c" + std::to_string(s.camera)
                                     : "");
      bars.categories.push_back(label);
      bars.values[0].push_back(s.figures.mergedAll.completeness);
      bars.values[1].push_back(ratioOrNaN(s.figures.merged2, s.figures.merged2.completeness));
      bars.values[2].push_back(ratioOrNaN(s.figures.merged3, s.figures.merged3.completeness));
    }
    plot("completeness.png", [&](const fs::path& f) { return plots::writeBarChart(f, bars); });
    image("completeness per scene", "completeness.png");
    md << "\n### Depth error maps\n\n"
          "Merged depth − truth, ±2 mm full scale (blue nearer, red farther); grey: no depth.\n\n";
    for (const auto& s : r.scenes) {
      const std::string name = "error_" + slug(s.scene) + "_" + slug(s.rigFile) + "_cam" +
                               std::to_string(s.camera) + ".png";
      plot(name, [&](const fs::path& f) {
        return plots::writeErrorMap(
            f, s.errorMm, s.width, s.height, 2.0,
            s.scene + ", " + s.rigFile + ", cam" + std::to_string(s.camera));
      });
      image(s.scene + " error map", name);
    }
    md << "\n";
  }

  void flat(const eval::Report& r) {
    if (r.flat.empty() && r.distance.empty()) {
      return;
    }
    md << "## Flat targets\n\n"
          "The figures a depth-camera quality tool reports on a wall: fill rate (pixels with "
          "depth / pixels of the smooth lit target) and the RMS distance of the points to their "
          "least-squares plane (spatial noise), with the RMSE against the truth beside it. The "
          "target is the smooth lit surface at the image centre (truth depth within 2 cm of "
          "the centre's). The fit takes every pixel with depth, gross errors included, as a "
          "quality tool does, so a handful of wrong pixels shows in it where the RMSE (which "
          "leaves gross errors out) does not.\n\n"
          "| target | distance m | fill rate | plane-fit RMS mm | RMSE mm | RMSE disparity px |"
          " gross |\n|---|---|---|---|---|---|---|\n";
    auto row = [&](const eval::FlatRun& f) {
      md << "| " << f.target << " | " << fixed(f.distanceM, 2) << " | " << pct(f.fit.fillRate, 2)
         << " | " << fixed(f.fit.rmsMm, 3) << " | " << fixed(f.score.rmseMm, 3) << " | "
         << fixed(f.score.rmsDisparityPx, 3) << " | " << pct(f.score.grossRate, 2) << " |\n";
    };
    for (const auto& f : r.flat) {
      row(f);
    }
    for (const auto& f : r.distance) {
      row(f);
    }
    if (!r.distance.empty()) {
      plots::LineChart chart{"Error vs distance (plane, 2 patterns at 90 deg)",
                             "distance, m",
                             "mm",
                             {{"plane-fit RMS", {}, {}}, {"RMSE vs truth", {}, {}}},
                             true,
                             {},
                             {}};
      for (const auto& f : r.distance) {
        chart.series[0].x.push_back(f.distanceM);
        chart.series[0].y.push_back(f.fit.rmsMm);
        chart.series[1].x.push_back(f.distanceM);
        chart.series[1].y.push_back(f.score.rmseMm);
      }
      plot("error_vs_distance.png",
           [&](const fs::path& f) { return plots::writeLineChart(f, chart); });
      md << "\n";
      image("error vs distance", "error_vs_distance.png");
    }
    md << "\n";
  }

  void table2(const eval::Report& r) {
    if (r.table2.empty()) {
      return;
    }
    md << "## The paper's Table 2, measured\n\n"
          "A sphere (radius 15 cm) with stations at the corners of a regular tetrahedron around "
          "it, 0.9 m out; station i holds camera i and projector i "
          "(`tools/host/eval/include/smx/eval/table2.hpp` has the layout). nPmC uses the first n "
          "projectors and m cameras, all patterns on at "
          "once. Relative amount: inlier pixels summed over every projector–camera pair, in the "
          "paper's unit (one scan of the whole sphere = 100 %: the 1P1C amount is its "
          "completeness). Completeness: the share of the sphere's surface on which some inlier "
          "lands (equal-area bins of 1.5 cm²); \"geometric\" is the same from the truth, the "
          "most any decoder could get in this layout.\n\n"
          "| projectors | cameras | amount, measured | amount, paper | completeness, measured "
          "| geometric | completeness, paper | gross |\n|---|---|---|---|---|---|---|---|\n";
    plots::BarChart chart{"Table 2: relative completeness, measured vs the paper's model",
                          "completeness",
                          0,
                          1,
                          {},
                          {"measured", "geometric bound", "paper (modelled)"},
                          {{}, {}, {}}};
    for (const auto& t : r.table2) {
      md << "| " << t.projectors << " | " << t.cameras << " | " << pct(t.amountPaperUnit, 0)
         << " | " << pct(t.paperAmount, 0) << " | " << pct(t.completeness, 0) << " | "
         << pct(t.geometricCompleteness, 0) << " | " << pct(t.paperCompleteness, 0) << " | "
         << pct(t.grossRate, 2) << " |\n";
      chart.categories.push_back(std::to_string(t.projectors) + "P" + std::to_string(t.cameras) +
                                 "C");
      chart.values[0].push_back(t.completeness);
      chart.values[1].push_back(t.geometricCompleteness);
      chart.values[2].push_back(t.paperCompleteness);
    }
    md << "\nWhere it differs from the paper: the model lets every projector–camera pair add data. "
          "Here a camera decodes mostly its own station's projector. Another station's pattern "
          "reaches its view only near the limbs, obliquely, with the stripes nearly along its "
          "epipolar lines, and decodes little or wrongly there (the pairs below); those pairs "
          "also carry most of the gross errors. Completeness follows the model more closely, "
          "because each added station brings its own pair.\n\n";
    plot("table2_completeness.png",
         [&](const fs::path& f) { return plots::writeBarChart(f, chart); });
    md << "\n";
    image("Table 2 completeness", "table2_completeness.png");
    md << "\nPairs that delivered depth (camera–projector: inlier pixels / pixels the projector "
          "lights in that camera's view):\n\n";
    for (const auto& t : r.table2) {
      md << "- " << t.projectors << "P" << t.cameras << "C:";
      for (const auto& p : t.pairs) {
        md << " cam" << p.camera << "–proj" << p.projector << " " << p.inliers() << "/"
           << p.litPixels << ";";
      }
      for (std::size_t c = 0; c < t.dropped.size(); ++c) {
        for (const int p : t.dropped[c]) {
          md << " (cam" << c << " does not decode proj" << p << ": 3 patterns per camera at most)";
        }
      }
      md << "\n";
    }
    md << "\n";
  }

  void baselines(const eval::Report& r) {
    if (r.singleProjector.empty() && r.directColour.empty() && r.trueDirections.empty()) {
      return;
    }
    md << "## Baselines\n\n";
    if (!r.singleProjector.empty()) {
      md << "### One projector against several\n\n"
            "A conventional single-projector scanner against the same rig with more "
            "projectors, each rendered with only its projectors present: the share of "
            "everything the camera sees (every pixel with a surface, lit or not) that gets "
            "depth.\n\n"
            "| scene | rig | projectors | coverage of the view | relative amount | gross | RMSE "
            "disparity px |\n|---|---|---|---|---|---|---|\n";
      std::map<std::string, int> single;
      for (const auto& c : r.singleProjector) {
        const int inliers = c.view.valid - c.view.gross;
        if (c.projectors == 1) {
          single[c.scene] = inliers;
        }
        const int base = single[c.scene];
        md << "| " << c.scene << " | " << c.rigFile << " | " << c.projectors << " | "
           << pct(c.view.completeness) << " | "
           << (base > 0 ? fixed(static_cast<double>(inliers) / base, 2) : "–") << " | "
           << pct(c.view.grossRate, 2) << " | " << fixed(c.view.rmsDisparityPx, 3) << " |\n";
      }
      md << "\n";
    }
    if (!r.directColour.empty()) {
      md << "### Direct colour estimation against orientation demultiplexing\n\n"
            "The single-projector decoder's front end (hue classification, "
            "`algo/include/smx/algo/direct_colour.hpp`) on the superposed image, given the "
            "demultiplexer's own "
            "directions, so only the colour decision differs. Boundaries of each projector "
            "scored against the truth where exactly n patterns light the surface.\n\n"
            "| scene | projector | lit by | demux recall | demux class accuracy | direct recall "
            "| direct precision | direct class accuracy |\n|---|---|---|---|---|---|---|---|\n";
      for (const auto& b : r.directColour) {
        md << "| " << b.scene << " | proj" << b.projector << " | " << b.patterns << " | "
           << pct(b.demux.recall) << " | " << pct(b.demux.classAccuracy) << " | "
           << pct(b.other.recall) << " | " << pct(b.other.precision) << " | "
           << pct(b.other.classAccuracy) << " |\n";
      }
      md << "\n";
    }
    if (!r.trueDirections.empty()) {
      md << "### True directions instead of estimated ones\n\n"
            "The same pipeline with its per-tile encoding directions taken from the truth "
            "(`Demultiplexer::fixTileDirections`): what direction estimation costs.\n\n"
            "| scene | directions | completeness, smooth | gross | RMSE disparity px | boundary "
            "recall (mean) | boundary position RMS px (mean) |\n|---|---|---|---|---|---|---|\n";
      for (const auto& t : r.trueDirections) {
        for (const bool truth : {false, true}) {
          const auto& f = truth ? t.truth : t.estimated;
          double recall = 0;
          double rms = 0;
          for (const auto& b : t.boundaries) {
            recall += (truth ? b.other : b.demux).recall / static_cast<double>(t.boundaries.size());
            rms += (truth ? b.other : b.demux).positionRmsPx /
                   static_cast<double>(t.boundaries.size());
          }
          md << "| " << t.scene << " | " << (truth ? "true" : "estimated") << " | "
             << completeness(f.mergedSmooth) << " | " << pct(f.mergedAll.grossRate, 2) << " | "
             << fixed(f.mergedAll.rmsDisparityPx, 3) << " | " << pct(recall, 2) << " | "
             << fixed(rms, 3) << " |\n";
        }
      }
      md << "\n";
    }
  }

  void sweeps(const eval::Report& r) {
    if (r.sweeps.empty()) {
      return;
    }
    md << "## Robustness sweeps\n\n"
          "One condition varied at a time from the sphere scene's (a sphere before a wall, "
          "rig_2proj_1cam). \"Usable\": smooth completeness ≥ "
       << pct(kUsableCompleteness, 0) << " and gross errors ≤ " << pct(kUsableGross, 0) << ".\n\n";
    for (const auto& s : r.sweeps) {
      md << "### " << s.name << "\n\n"
         << s.quantity << ".\n\n"
         << "| value | stripe width px | completeness, smooth | lit by 2 | gross | RMSE "
            "disparity px | usable |\n|---|---|---|---|---|---|---|\n";
      plots::LineChart chart{"Sweep: " + s.name,
                             s.quantity,
                             "share",
                             {{"completeness, smooth", {}, {}},
                              {"completeness, lit by 2", {}, {}},
                              {"gross errors x 10", {}, {}}},
                             true,
                             {},
                             std::pair{0.0, 1.0}};
      for (const auto& p : s.points) {
        const auto& f = p.figures;
        md << "| " << fixed(p.value, 2) << " | " << fixed(p.stripeWidthPx, 2) << " | "
           << completeness(f.mergedSmooth) << " | " << completeness(f.merged2) << " | "
           << pct(f.mergedAll.grossRate, 2) << " | " << fixed(f.mergedAll.rmsDisparityPx, 3)
           << " | " << (usable(f) ? "yes" : "**no**") << " |\n";
        chart.series[0].x.push_back(p.value);
        chart.series[0].y.push_back(f.mergedSmooth.completeness);
        chart.series[1].x.push_back(p.value);
        chart.series[1].y.push_back(f.merged2.completeness);
        chart.series[2].x.push_back(p.value);
        chart.series[2].y.push_back(std::min(1.0, 10.0 * f.mergedAll.grossRate));
      }
      std::string unusable;
      for (const auto& p : s.points) {
        if (!usable(p.figures)) {
          unusable += (unusable.empty() ? "" : ", ") + fixed(p.value, 2);
        }
      }
      md << "\n"
         << (unusable.empty() ? "Usable over the whole range." : "Not usable at: " + unusable + ".")
         << "\n";
      const std::string name = "sweep_" + slug(s.name) + ".png";
      plot(name, [&](const fs::path& f) { return plots::writeLineChart(f, chart); });
      md << "\n";
      image("sweep " + s.name, name);
      md << "\n";
    }
  }
};

// The targets for the realism suite (fixed seed, the paper's noise).
constexpr double kTargetGrossAggregate = 0.001;
constexpr double kTargetGrossEachCase = 0.005;
constexpr double kTargetResolvableAggregate = 0.95;
constexpr double kTargetResolvableEachCase = 0.85;
constexpr double kTargetLitBy3 = 0.90;
constexpr double kTargetDisparityPx = 0.15;
// Error maps of the realism suite: the gross-error threshold's order, so that gross errors
// saturate and sub-millimetre ones still show.
constexpr double kRealismErrorRangeMm = 5.0;

std::string realismRow(const std::string& head, const std::vector<double>& stripes,
                       const eval::RealismRun& r) {
  std::string widths;
  for (std::size_t p = 0; p < stripes.size(); ++p) {
    widths += (p == 0 ? "" : " / ") + fixed(stripes[p], 1);
  }
  return head + " | " + widths + " | " + completeness(r.lit) + " | " + completeness(r.smooth) +
         " | " + completeness(r.lit2) + " | " + completeness(r.lit3) + " | " +
         completeness(r.resolvable) + " | " + pct(r.lit.grossRate, 2) + " | " +
         pct(r.outsideBand.grossRate, 2) + " | " + fixed(r.lit.rmseMm, 2) + " | " +
         fixed(r.lit.rmsDisparityPx, 3) + " |\n";
}

// Shares per first cause, "n / s / d / g / o" in percent; "–" when there is nothing to share.
std::string causeShares(const eval::Attribution& a, bool gross) {
  std::string out;
  for (int c = 0; c < eval::kCauses; ++c) {
    const auto cause = static_cast<eval::Cause>(c);
    const double share = gross ? eval::grossShare(a, cause) : eval::missingShare(a, cause);
    out += (c == 0 ? "" : " / ") + fixed(100.0 * share, 0);
  }
  return out;
}

std::string attributionRow(const std::string& head, const eval::Attribution& a) {
  int gross = 0;
  int missing = 0;
  for (int c = 0; c < eval::kCauses; ++c) {
    gross += a.outsideBand[static_cast<std::size_t>(c)].gross;
    missing += a.resolvable[static_cast<std::size_t>(c)].missing();
  }
  return head + " | " + std::to_string(gross) + " | " + (gross > 0 ? causeShares(a, true) : "–") +
         " | " + std::to_string(missing) + " | " + (missing > 0 ? causeShares(a, false) : "–") +
         " |\n";
}

// One field of every run the pipeline did not refuse.
template <class T>
std::vector<T> ofScoredRuns(const eval::RealismReport& s, T eval::RealismRun::*field) {
  std::vector<T> out;
  for (const auto& run : s.runs) {
    if (!run.refused) {
      out.push_back(run.*field);
    }
  }
  return out;
}

void attributionSection(std::ostream& md, const eval::RealismReport& s) {
  const auto sum = eval::sumAttributions(ofScoredRuns(s, &eval::RealismRun::attribution));
  md << "### What stops the targets\n\n"
        "Each gross pixel outside the band and each resolvable pixel without depth goes to the "
        "first condition it meets, all from the truth and the camera image, never from the "
        "decoder (`tools/host/eval/include/smx/eval/realism_attribution.hpp`): **narrow** some "
        "lighting projector's stripes are under "
     << fixed(eval::kNarrowStripePx, 1)
     << " px wide in the camera (truth stripe gradient); **single** one projector lights it; "
        "**dim** the camera image's 3 × 3 box means within "
     << eval::kDimWindowRadiusPx << " px of it span under " << eval::kDimContrastDn
     << " DN in every colour channel; **grazing** the truth normal is more than "
     << fixed(eval::kGrazingDeg, 0)
     << "° from the camera ray or from every lighting projector's ray; **edge** within "
     << eval::kNearEdgePx
     << " px of a depth discontinuity of the truth; **triple** three projectors light it; "
        "**other** none of these. Shares in % as narrow / single / dim / grazing / edge / "
        "triple / other.\n\n"
        "| case | cam | scene | gross outside band, px | shares | missing resolvable, px | "
        "shares |\n|---|---|---|---|---|---|---|\n";
  for (const auto& run : s.runs) {
    if (!run.refused) {
      md << attributionRow("| " + std::to_string(run.caseIndex) + " | cam" +
                               std::to_string(run.camera) + " | " + run.summary,
                           run.attribution);
    }
  }
  md << attributionRow("| **all** | |", sum)
     << "\nThe aggregate figures with every pixel meeting a condition removed (whatever its "
        "place in the order):\n\n"
        "| pixels removed | gross outside band | completeness, resolvable |\n|---|---|---|\n"
     << "| none | " << pct(eval::grossRateWithout(sum, std::nullopt), 3) << " | "
     << pct(eval::completenessWithout(sum, std::nullopt)) << " |\n";
  for (int c = 0; c < eval::kNamedCauses; ++c) {
    const auto cause = static_cast<eval::Cause>(c);
    md << "| " << eval::causeName(cause) << " | " << pct(eval::grossRateWithout(sum, cause), 3)
       << " | " << pct(eval::completenessWithout(sum, cause)) << " |\n";
  }
  md << "| all six | " << pct(eval::grossRateWithout(sum, eval::Cause::kOther), 3) << " | "
     << pct(eval::completenessWithout(sum, eval::Cause::kOther)) << " |\n\n";
}

void wrongDepthSection(std::ostream& md, const eval::RealismReport& s) {
  const auto sum = eval::sumWrongDepth(ofScoredRuns(s, &eval::RealismRun::wrongDepth));
  const int total = sum.total();
  const auto cell = [total](int n) {
    return std::to_string(n) + " (" + pct(total > 0 ? static_cast<double>(n) / total : 0.0) + ")";
  };
  md << "### What the wrong depths are\n\n"
        "Each gross pixel outside the band, judged against the truth stripe coordinate of the "
        "first projector with depth there (`tools/host/eval/include/smx/eval/wrong_depth.hpp`): "
        "**level** its decoded coordinate is "
     << fixed(eval::kLevelErrorStripes, 1)
     << " stripe or more off (a wrong stripe level), **position** less (the right level, its "
        "boundaries misplaced), **unlit** that projector does not light the pixel; **alone** no "
        "other projector has depth there, **corroborated** others do. Pixels and shares of all "
        "the gross pixels outside the band.\n\n| depth from";
  for (int k = 0; k < eval::kWrongKinds; ++k) {
    md << " | " << eval::wrongKindName(static_cast<eval::WrongKind>(k));
  }
  md << " | all |\n|---|---|---|---|---|\n";
  const char* names[] = {"alone", "corroborated"};
  std::array<int, eval::kWrongKinds> kinds{};
  for (std::size_t a = 0; a < sum.gross.size(); ++a) {
    int row = 0;
    md << "| " << names[a];
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      md << " | " << cell(sum.gross[a][k]);
      row += sum.gross[a][k];
      kinds[k] += sum.gross[a][k];
    }
    md << " | " << cell(row) << " |\n";
  }
  md << "| all";
  for (const int k : kinds) {
    md << " | " << cell(k);
  }
  md << " | " << cell(total) << " |\n\n";
}

void realismSection(Writer& w, const eval::Report& r) {
  const auto& s = r.realism;
  if (s.runs.empty()) {
    return;
  }
  auto& md = w.md;
  md << "## Realism suite\n\n"
     << s.cases << " scenes and rigs generated from the seed " << r.seed
     << " (`tools/host/eval/include/smx/eval/realism_case.hpp` has the envelope: 2–3 projectors "
        "60–90° apart, 1–2 cameras, baselines 8–25 cm, working distance 0.5–1.2 m, stripes "
        "3–8 px in the camera there, lens shift and distortion, the bunny, the head and "
        "primitives before walls and oblique floors, optics from the simulator's ranges), "
        "projector lens distortion "
     << (s.generator.projectorDistortion ? "on" : "off") << ", the paper's noise"
     << Writer::samplingNote(r)
     << ". Each camera decoded by the firmware's pipeline with its directions predicted at the "
        "case's working distance; the merged range image scored against the truth "
        "(`tools/host/eval/include/smx/eval/realism_eval.hpp`). \"resolvable\": smooth lit "
        "pixels where every lighting projector's stripes are at least "
     << fixed(eval::kResolvableStripePx, 1)
     << " px wide in the camera (truth); \"gross outside band\": gross errors among the lit "
        "pixels farther than "
     << eval::kDiscontinuityBandPx
     << " px from a depth discontinuity of the truth. Aggregates are sums of the pixel counts "
        "over all runs, not means of the ratios.\n\n";

  std::vector<eval::DepthScore> lit;
  std::vector<eval::DepthScore> smooth;
  std::vector<eval::DepthScore> lit2;
  std::vector<eval::DepthScore> lit3;
  std::vector<eval::DepthScore> resolvable;
  std::vector<eval::DepthScore> band;
  int refused = 0;
  double worstGross = 0;
  double worstResolvable = 1;
  int grossOver = 0;
  int resolvableUnder = 0;
  for (const auto& run : s.runs) {
    if (run.refused) {
      ++refused;
      continue;
    }
    lit.push_back(run.lit);
    smooth.push_back(run.smooth);
    lit2.push_back(run.lit2);
    lit3.push_back(run.lit3);
    resolvable.push_back(run.resolvable);
    band.push_back(run.outsideBand);
    worstGross = std::max(worstGross, run.outsideBand.grossRate);
    grossOver += run.outsideBand.grossRate > kTargetGrossEachCase ? 1 : 0;
    if (run.resolvable.regionPixels >= kMinRegionPixels) {
      worstResolvable = std::min(worstResolvable, run.resolvable.completeness);
      resolvableUnder += run.resolvable.completeness < kTargetResolvableEachCase ? 1 : 0;
    }
  }
  const auto sLit = eval::sumScores(lit);
  const auto sSmooth = eval::sumScores(smooth);
  const auto sLit2 = eval::sumScores(lit2);
  const auto sLit3 = eval::sumScores(lit3);
  const auto sResolvable = eval::sumScores(resolvable);
  const auto sBand = eval::sumScores(band);
  const std::size_t decoded = s.runs.size() - static_cast<std::size_t>(refused);

  md << "### Aggregate and targets\n\n"
        "| figure | aggregate | target (aggregate) | worst run | target (every run) | runs "
        "missing it |\n|---|---|---|---|---|---|\n"
     << "| gross outside band | " << pct(sBand.grossRate, 3) << " | ≤ "
     << pct(kTargetGrossAggregate, 1) << " | " << pct(worstGross, 2) << " | ≤ "
     << pct(kTargetGrossEachCase, 1) << " | " << grossOver << " of " << decoded << " |\n"
     << "| completeness, resolvable | " << pct(sResolvable.completeness) << " | ≥ "
     << pct(kTargetResolvableAggregate, 0) << " | " << pct(worstResolvable) << " | ≥ "
     << pct(kTargetResolvableEachCase, 0) << " | " << resolvableUnder << " of " << decoded << " |\n"
     << "| completeness, lit by 3 (smooth) | " << completeness(sLit3) << " | ≥ "
     << pct(kTargetLitBy3, 0) << " (curved surfaces) | | | |\n"
     << "| RMSE disparity px | " << fixed(sLit.rmsDisparityPx, 3) << " | ≤ "
     << fixed(kTargetDisparityPx, 2) << " | | | |\n"
     << "| completeness, all lit | " << completeness(sLit) << " | | | | |\n"
     << "| completeness, smooth | " << completeness(sSmooth) << " | | | | |\n"
     << "| completeness, lit by 2 (smooth) | " << completeness(sLit2) << " | | | | |\n"
     << "| gross, all lit | " << pct(sLit.grossRate, 2) << " | | | | |\n"
     << "| RMSE mm | " << fixed(sLit.rmseMm, 2) << " | | | | |\n"
     << "| runs refused by the pipeline | " << refused << " of " << s.runs.size()
     << " | | | | |\n\n";
  attributionSection(md, s);
  wrongDepthSection(md, s);

  md << "### Per run\n\n"
        "Rig: per projector the baseline to this camera, its encoding axis in cam0 and the "
        "designed stripe width in cam0 at the working distance; stripe px: the median width in "
        "this camera over the pixels each projector lights (truth).\n\n"
        "| case | cam | scene | rig | stripe px | completeness, all lit | smooth | lit by 2 | "
        "lit by 3 | resolvable | gross | gross outside band | RMSE mm | RMSE disparity px |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& run : s.runs) {
    const std::string head = "| " + std::to_string(run.caseIndex) + " | cam" +
                             std::to_string(run.camera) + " | " + run.summary + " | " + run.rig;
    if (run.refused) {
      md << head << " | refused: " << run.reason << " | | | | | | | | | |\n";
    } else {
      md << realismRow(head, run.medianStripePx, run);
    }
  }
  md << realismRow("| **all** | | | " + std::to_string(decoded) + " runs", {}, [&] {
    eval::RealismRun t;
    t.lit = sLit;
    t.smooth = sSmooth;
    t.lit2 = sLit2;
    t.lit3 = sLit3;
    t.resolvable = sResolvable;
    t.outsideBand = sBand;
    return t;
  }());

  md << "\n### The " << eval::kRealismWorstShown
     << " worst runs (gross errors outside the band)\n\n"
        "Camera image, then merged depth − truth, ±"
     << fixed(kRealismErrorRangeMm, 0)
     << " mm full scale (blue nearer, red farther); grey: no "
        "depth.\n\n";
  for (const auto* run : eval::worstRuns(s.runs, eval::kRealismWorstShown)) {
    if (run->errorMm.empty()) {
      continue;
    }
    const std::string id =
        "case" + std::to_string(run->caseIndex) + "_cam" + std::to_string(run->camera);
    md << "- case " << run->caseIndex << ", cam" << run->camera << " (" << run->summary
       << "): gross outside band " << pct(run->outsideBand.grossRate, 2) << ", resolvable "
       << completeness(run->resolvable) << "\n\n";
    w.plot("realism_" + id + ".png",
           [&](const fs::path& f) { return sim::writePngRgb8(f, run->image.view()); });
    w.plot("realism_error_" + id + ".png", [&](const fs::path& f) {
      return plots::writeErrorMap(f, run->errorMm, run->image.width, run->image.height,
                                  kRealismErrorRangeMm, "realism " + id);
    });
    w.image("realism " + id + " camera", "realism_" + id + ".png");
    w.image("realism " + id + " error map", "realism_error_" + id + ".png");
    md << "\n";
  }
  md << "\n";
}

// Plots of an earlier run that this one did not make must not linger; other files stay.
void removeStalePlots(const fs::path& results, const std::set<std::string>& written) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(results, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".png" && !written.contains(name) &&
        (name.starts_with("error_") || name.starts_with("sweep_") || name.starts_with("table2") ||
         name.starts_with("realism_") || name == "completeness.png")) {
      fs::remove(entry.path(), ec);
    }
  }
}

}  // namespace

std::expected<void, std::string> writeEvalReport(const fs::path& dir, const eval::Report& report,
                                                 const std::string& command) {
  auto top = OutputFolder::create(dir);
  if (!top) {
    return std::unexpected(top.error());
  }
  auto results = OutputFolder::create(dir / "results");
  if (!results) {
    return std::unexpected(results.error());
  }
  Writer w{*results, {}, {}, {}};
  w.md << "# stripemux: evaluation results\n\n"
          "Measured on the simulator's renders with the firmware's own per-frame pipeline. "
          "Regenerate with\n\n```\n"
       << command
       << "\n```\n\n"
          "Definitions (docs/results.md is generated; the code is tools/host/eval/): "
          "completeness = pixels with depth / pixels of the region (lit by ≥ 1 projector: every "
          "pixel; \"smooth\": 3 px inside, away from depth jumps); gross = |z − z_truth| > "
          "max(5 mm, 1 %), as a share of the pixels with depth; RMSE over the others, in mm and "
          "as the equivalent disparity error in camera pixels (f·b·|Δz| / z²). \"–\": the "
          "frame has fewer than "
       << kMinRegionPixels << " pixels in that region.\n\n";
  w.scenes(report);
  w.flat(report);
  w.table2(report);
  w.baselines(report);
  w.sweeps(report);
  realismSection(w, report);
  if (!w.error.empty()) {
    return std::unexpected(w.error);
  }
  if (auto ok = top->writeText("results.md", w.md.str()); !ok) {
    return ok;
  }
  if (auto ok = results->commit(); !ok) {
    return ok;
  }
  removeStalePlots(results->path(), w.written);
  return top->commit();
}

}  // namespace smx::host
