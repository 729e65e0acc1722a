// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// `palpate study` on the shipped beam (--quick, 24 HIP positions): the
// study measures what it says. Checked:
// - every knob is there: grid spacing 5/10/20 mm with both
//   interpolations, tolerance, staging, the combination, the mesh (twice
//   the subdivisions) and the element (P2), each with its errors and costs;
// - Hermite is at least as accurate as trilinear at every spacing, its
//   error falls at least 8x from 10 to 5 mm (fourth order: 16x) and
//   trilinear's at least 3x (second order: 4x);
// - Hermite at 10 mm is at least as accurate as trilinear at 5 mm (the
//   issue's target);
// - the recommended setting passes the 3.5 % threshold, and no passing
//   setting is faster;
// - the CSV has a header and one line per row;
// - the point probe's discretisation error is not bounded (none converges);
//   with a sphere on the beam lying on its bottom face, the study measures
//   the discretisation error of the scene's mesh and element (the larger
//   of the two knobs' p95 difference to the finer variant), reports it,
//   and a recommendation keeps the total within 3.5 %.

#include <palpate/app/study.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "../tests.h"

namespace
{
  const palpate::StudyRow *
  find_in(const palpate::StudyResult &r,
          const std::string          &knob,
          const std::string          &value,
          const std::string          &probe)
  {
    for (const auto &row : r.rows)
      if (row.knob == knob && row.value == value && row.probe == probe)
        return &row;
    return nullptr;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene  scene = shipped_scene("beam.prm");
  palpate::StudyOptions options;
  options.quick    = true;
  options.samples  = 24;
  options.progress = false;
  options.plot     = false;
  options.csv_file = "study.csv";
  std::ostringstream         out;
  const palpate::StudyResult r = palpate::run_study(out, scene, options);

  const auto find = [&](const std::string &knob,
                        const std::string &value,
                        const std::string &interpolation,
                        const std::string &probe = "point") {
    for (const auto &row : r.rows)
      if (row.knob == knob && row.value == value &&
          row.interpolation == interpolation && row.probe == probe)
        return &row;
    return static_cast<const palpate::StudyRow *>(nullptr);
  };
  bool all = true;
  for (const auto &[knob, value, scheme] :
       std::vector<std::array<std::string, 3>>{
         {"grid", "5 mm", "trilinear"},
         {"grid", "5 mm", "Hermite"},
         {"grid", "10 mm", "trilinear"},
         {"grid", "10 mm", "Hermite"},
         {"grid", "20 mm", "trilinear"},
         {"grid", "20 mm", "Hermite"},
         {"tolerance", "1e-04", "Hermite"},
         {"increment", "2.5 mm", "Hermite"},
         {"mesh", "scene mesh", "direct"},
         {"element", "P2", "direct"}})
    {
      const auto *row = find(knob, value, scheme);
      const bool  good =
        row != nullptr && row->samples > 0 && row->covered > 0 &&
        std::isfinite(row->err_p95_pct) && row->state_ms > 0 &&
        (scheme == "direct" || (row->speed_mm_s > 0 && row->region_states > 0));
      if (!good)
        deallog << "missing or empty: " << knob << " " << value << " " << scheme
                << std::endl;
      all = all && good;
    }
  deallog << "every knob measured, errors and costs: " << ok(all) << std::endl;

  bool hermite_better = true;
  for (const std::string h : {"5 mm", "10 mm", "20 mm"})
    hermite_better =
      hermite_better && find("grid", h, "Hermite")->err_p95_N <=
                          find("grid", h, "trilinear")->err_p95_N;
  deallog << "Hermite at least as accurate as trilinear at every spacing: "
          << ok(hermite_better) << std::endl;
  const double hermite_rate = find("grid", "10 mm", "Hermite")->err_max_N /
                              find("grid", "5 mm", "Hermite")->err_max_N;
  const double trilinear_rate = find("grid", "10 mm", "trilinear")->err_max_N /
                                find("grid", "5 mm", "trilinear")->err_max_N;
  deallog << "halving h: Hermite error falls >= 8x: " << ok(hermite_rate >= 8)
          << ", trilinear >= 3x: " << ok(trilinear_rate >= 3) << std::endl;
  deallog << "Hermite at 10 mm at least as accurate as trilinear at 5 mm: "
          << ok(find("grid", "10 mm", "Hermite")->err_p95_N <=
                find("grid", "5 mm", "trilinear")->err_p95_N)
          << std::endl;

  bool best = r.recommended >= 0;
  if (best)
    {
      const auto &rec = r.rows[r.recommended];
      best            = rec.err_p95_pct <= 3.5;
      for (const auto &row : r.rows)
        if (row.interpolation != "direct" &&
            row.covered >= 0.95 * row.samples && row.err_p95_pct <= 3.5)
          best = best && row.speed_mm_s <= rec.speed_mm_s;
    }
  deallog << "the recommendation passes and is the fastest that does: "
          << ok(best) << std::endl;

  std::ifstream csv("study.csv");
  std::string   line;
  unsigned int  lines = 0;
  while (std::getline(csv, line))
    ++lines;
  deallog << "CSV: a header and one line per row: "
          << ok(lines == r.rows.size() + 1) << std::endl;
  deallog << "a point probe's discretisation error is not bounded: "
          << ok(r.discretization_pct < 0) << std::endl;

  // A sphere on the beam lying on its bottom face: the study measures the
  // discretisation error of the scene's mesh and element for the sphere,
  // and its recommendation (if any) keeps the total within 3.5 %.
  palpate::Scene sphere = shipped_scene("beam.prm");
  touch_beam_with_sphere(sphere, 0.01);
  options.samples  = 8;
  options.csv_file = "study-sphere.csv";
  std::ostringstream         sphere_out;
  const palpate::StudyResult s =
    palpate::run_study(sphere_out, sphere, options);
  const auto *element = find_in(s, "element", "P1", "tip 10 mm");
  deallog << "sphere: discretisation error measured, the larger of mesh and "
             "element: "
          << ok(s.discretization_pct >= 0 && element != nullptr &&
                s.discretization_pct >= element->err_p95_pct)
          << "; reported: "
          << ok(sphere_out.str().find("Discretisation error") !=
                std::string::npos)
          << "; the recommendation's total within 3.5 %: "
          << ok(s.recommended < 0 ||
                s.rows[s.recommended].err_p95_pct + s.discretization_pct <= 3.5)
          << std::endl;
}
