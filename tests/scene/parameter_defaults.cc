// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The declared defaults round-trip: `palpate --print-parameters` writes a
// scene with every entry at its default; reading that file back must
// succeed (every default matches its own pattern and passes the scene's
// checks) and give exactly the declared values. Every entry must be
// documented.

#include <palpate/scene/parameters.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <regex>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  {
    std::ofstream out("defaults.prm");
    palpate::print_parameters(out, palpate::ParameterFormat::prm);
  }
  const palpate::Scene scene = palpate::Scene::read("defaults.prm");
  deallog << "defaults.prm parses and passes the scene checks" << std::endl;

  // The value tree after parsing the printed file equals the declared one.
  dealii::ParameterHandler declared, parsed;
  palpate::Parameters::AllParameters::declare_parameters(declared);
  palpate::Parameters::AllParameters::declare_parameters(parsed);
  parsed.parse_input("defaults.prm");
  std::ostringstream a, b;
  declared.print_parameters(a, dealii::ParameterHandler::XML);
  parsed.print_parameters(b, dealii::ParameterHandler::XML);
  deallog << "values after the round trip equal the declared defaults: "
          << (a.str() == b.str() ? "yes" : "NO") << std::endl;

  // Count entries and undocumented ones in the declarations.
  const std::string xml   = a.str();
  const auto        count = [&](const std::string &pattern) {
    const std::regex r(pattern);
    return std::distance(std::sregex_iterator(xml.begin(), xml.end(), r),
                         std::sregex_iterator());
  };
  deallog << "declared entries: " << count("<pattern_description>")
          << std::endl;
  deallog << "entries without documentation: " << count("<documentation/>")
          << std::endl;

  // A few parsed defaults, as the structs see them.
  const auto &p = scene.parameters;
  deallog << "Mesh/Source = " << p.mesh.source << std::endl;
  deallog << "Material model/Model name = " << p.material_model.model_name
          << ", E = "
          << p.material_model.get_double("St.Venant-Kirchhoff",
                                         "Young's modulus")
          << " Pa, nu = "
          << p.material_model.get_double("St.Venant-Kirchhoff",
                                         "Poisson's ratio")
          << std::endl;
  deallog << "Active node/Point = "
          << palpate::Utilities::to_string(
               p.boundary_conditions.active_node.point)
          << std::endl;
  deallog << "Nonlinear solver: " << p.nonlinear_solver.max_newton_iterations
          << " iterations, residual tolerance "
          << p.nonlinear_solver.residual_tolerance << std::endl;
  deallog << "Linear solver = " << p.linear_solver.solver << " ("
          << p.linear_solver.ordering << ")" << std::endl;
  deallog << "Haptics: " << p.haptics.loop_rate << " Hz, force limit "
          << p.haptics.force_limit << " N" << std::endl;

  // The default-constructed scene is the same as the parsed one.
  const palpate::Scene defaults;
  deallog << "default-constructed scene agrees: "
          << ((defaults.parameters.mesh.source == p.mesh.source &&
               defaults.parameters.state_space.grid_spacing ==
                 p.state_space.grid_spacing &&
               defaults.parameters.scheduler.cloud_radius ==
                 p.scheduler.cloud_radius) ?
                "yes" :
                "NO")
          << std::endl;
}
