// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A scene variant from the command line (`--set ENTRY=VALUE`, issue 27)
// is the same scene as a copy of the file with those lines changed: the
// same parameters and, solved, the same force to the last bit. The
// entries it changes are listed and have no line in the file; the
// entries it does not touch keep the file's values.

#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <regex>

#include "../tests.h"

namespace
{
  palpate::Utilities::Point3
  force(const palpate::Scene &scene)
  {
    const Body           body(scene);
    palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
    const palpate::State s = solver.solve(solver.rest_state(), {{0, 0, -0.01}});
    return s.force;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const std::string file = palpate_source_dir + "/parameters/paper-stvk.prm";
  const std::vector<std::string> settings = {
    "Material model/Model name=Neo-Hookean",
    "Material model / Neo-Hookean / Young's modulus = 20000",
    "Nonlinear solver/Residual tolerance=1e-6"};
  const palpate::Scene variant = palpate::Scene::read(file, settings);

  // The same by editing a copy of the file: the model line changed, the
  // other two added in their subsections.
  std::string text = read_file(file);
  text             = std::regex_replace(text,
                            std::regex("set Model name = St.Venant-Kirchhoff"),
                            "set Model name = Neo-Hookean\n"
                                        "  subsection Neo-Hookean\n"
                                        "    set Young's modulus = 20000\n"
                                        "  end");
  text             = std::regex_replace(text,
                            std::regex("subsection Nonlinear solver\n"),
                            "subsection Nonlinear solver\n"
                                        "  set Residual tolerance = 1e-6\n");
  // Here, with the mesh's path made absolute (the file's is relative to
  // parameters/).
  text                   = std::regex_replace(text,
                            std::regex("\\.\\./meshes/"),
                            palpate_meshes_dir + "/");
  const std::string copy = "edited.prm";
  write_file(copy, text);
  const palpate::Scene edited = palpate::Scene::read(copy);
  std::remove(copy.c_str());
  const palpate::Scene original = palpate::Scene::read(file);

  const auto &v = variant.parameters, &e = edited.parameters,
             &o = original.parameters;
  deallog << "model: " << v.material_model.model_name
          << " (the edited copy: " << e.material_model.model_name
          << ", the file: " << o.material_model.model_name << ")" << std::endl;
  deallog << "residual tolerance: " << v.nonlinear_solver.residual_tolerance
          << " (the edited copy: " << e.nonlinear_solver.residual_tolerance
          << ", the file: " << o.nonlinear_solver.residual_tolerance << ")"
          << std::endl;
  deallog << "untouched entries keep the file's values (grid spacing "
          << v.state_space.grid_spacing << ", scale factor "
          << v.mesh.scale_factor << "): "
          << ok(v.state_space.grid_spacing == o.state_space.grid_spacing &&
                v.mesh.scale_factor == o.mesh.scale_factor)
          << std::endl;
  deallog << "listed as set on the command line:" << std::endl;
  for (const auto &s : variant.command_line_settings())
    deallog << "  " << s << std::endl;
  deallog << "no line in the file for them: "
          << ok(variant.line_of("Material model/Model name") == 0 &&
                original.line_of("Material model/Model name") > 0)
          << std::endl;

  // A value is taken whole: '#' starts no comment, as it would in a file.
  const palpate::Scene hash =
    palpate::Scene::read(file, {"Output/Directory=run#2"});
  deallog << "a value holding '#' stays whole: "
          << ok(hash.parameters.output.directory == "run#2") << std::endl;

  const auto a = force(variant), b = force(edited), c = force(original);
  deallog << "force of the variant: (" << palpate::Utilities::to_string(a, 6)
          << ") N" << std::endl;
  deallog << "the same as the edited copy's, bit for bit: "
          << ok(a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) << std::endl;
  deallog << "different from the file's own ("
          << palpate::Utilities::to_string(c, 6)
          << " N): " << ok(a[0] != c[0] || a[1] != c[1] || a[2] != c[2])
          << std::endl;
}
