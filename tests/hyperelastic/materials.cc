// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The material laws against their own definitions: P = dW/dF and
// A = dP/dF by central finite differences (relative error < 1e-6 at
// random deformations, including strong compression), and at F = I the
// tangent is Hooke's tensor lambda d_iJ d_kL + mu (d_ik d_JL + d_iL d_kJ)
// (for the isochoric Mooney-Rivlin energy its deviatoric part,
// lambda = -2 mu/3). Every registered material plug-in, with its default
// constants, is checked: a new material gets these checks for free.

#include <palpate/hyperelastic/material.h>

#include <cmath>
#include <random>

#include "../tests.h"

namespace
{
  using palpate::Tensor;

  double
  check_stress(const palpate::Material &m, const Tensor<2, 3> &F)
  {
    Tensor<2, 3> P, Pp, Pm;
    m.evaluate(F, P, nullptr);
    double error = 0, size = 0;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int J = 0; J < 3; ++J)
        {
          const double h  = 1e-6;
          Tensor<2, 3> Fp = F, Fm = F;
          Fp[i][J] += h, Fm[i][J] -= h;
          const double fd =
            (m.evaluate(Fp, Pp, nullptr) - m.evaluate(Fm, Pm, nullptr)) /
            (2 * h);
          error = std::max(error, std::abs(fd - P[i][J]));
          size  = std::max(size, std::abs(P[i][J]));
        }
    return error / size;
  }

  double
  check_tangent(const palpate::Material &m, const Tensor<2, 3> &F)
  {
    Tensor<2, 3> P, Pp, Pm;
    Tensor<4, 3> A;
    m.evaluate(F, P, &A);
    double error = 0, size = 0;
    for (unsigned int k = 0; k < 3; ++k)
      for (unsigned int L = 0; L < 3; ++L)
        {
          const double h  = 1e-6;
          Tensor<2, 3> Fp = F, Fm = F;
          Fp[k][L] += h, Fm[k][L] -= h;
          m.evaluate(Fp, Pp, nullptr);
          m.evaluate(Fm, Pm, nullptr);
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int J = 0; J < 3; ++J)
              {
                const double fd = (Pp[i][J] - Pm[i][J]) / (2 * h);
                error           = std::max(error, std::abs(fd - A[i][J][k][L]));
                size            = std::max(size, std::abs(A[i][J][k][L]));
              }
        }
    return error / size;
  }

  double
  hooke_error(const palpate::Material &m, const double lambda, const double mu)
  {
    Tensor<2, 3> F, P;
    Tensor<4, 3> A;
    for (unsigned int i = 0; i < 3; ++i)
      F[i][i] = 1;
    m.evaluate(F, P, &A);
    double error = P.norm();
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int J = 0; J < 3; ++J)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int L = 0; L < 3; ++L)
            {
              const double hooke =
                lambda * (i == J) * (k == L) +
                mu * ((i == k) * (J == L) + (i == L) * (J == k));
              error = std::max(error, std::abs(A[i][J][k][L] - hooke));
            }
    return error / (lambda + 2 * mu);
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::StVenantKirchhoff stvk(15465, 0.49);
  const palpate::NeoHookean        nh(15465, 0.49);
  deallog << "Lame parameters for E = 15465 Pa, nu = 0.49: lambda = "
          << stvk.lambda << " Pa, mu = " << stvk.mu << " Pa" << std::endl;

  std::mt19937                           random(42);
  std::uniform_real_distribution<double> perturbation(-0.3, 0.3);
  for (const auto &plugin : palpate::MaterialRegistry::plugins())
    {
      const auto material = palpate::MaterialRegistry::create(plugin.name, {});
      deallog << plugin.name << ": " << material->description() << std::endl;
      double worst_stress = 0, worst_tangent = 0;
      for (unsigned int sample = 0; sample < 20; ++sample)
        {
          Tensor<2, 3> F;
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              F[i][j] = (i == j) + perturbation(random);
          if (sample % 4 == 0) // strong compression
            F *= 0.6;
          if (!(dealii::determinant(F) > 0.05))
            continue;
          worst_stress  = std::max(worst_stress, check_stress(*material, F));
          worst_tangent = std::max(worst_tangent, check_tangent(*material, F));
        }
      deallog << "  P = dW/dF, largest relative error < 1e-6: "
              << (worst_stress < 1e-6 ? "yes" : "NO") << std::endl;
      deallog << "  A = dP/dF, largest relative error < 1e-6: "
              << (worst_tangent < 1e-6 ? "yes" : "NO") << std::endl;
      // At F = I: Hooke's tensor of the small-strain mu and nu; for an
      // isochoric energy its deviatoric part, lambda = -2 mu / 3.
      const double mu     = material->shear_modulus();
      const double nu     = material->poissons_ratio();
      const double lambda = material->isochoric() ?
                              -2.0 * mu / 3.0 :
                              2.0 * mu * nu / (1.0 - 2.0 * nu);
      deallog
        << "  at F = I: P = 0 and A = Hooke's tensor, relative error < 1e-12: "
        << (hooke_error(*material, lambda, mu) < 1e-12 ? "yes" : "NO")
        << std::endl;
    }

  // Neo-Hookean is undefined for det F <= 0; St.Venant-Kirchhoff is
  // defined (palpate still rejects such states as inverted elements).
  Tensor<2, 3> inverted;
  inverted[0][0] = -1, inverted[1][1] = 1, inverted[2][2] = 1;
  deallog << "inverted F admissible: St.Venant-Kirchhoff "
          << stvk.admissible(inverted) << ", neo-Hookean "
          << nh.admissible(inverted) << std::endl;

  // Pure compression: St.Venant-Kirchhoff softens (its stress grows ever
  // more slowly and vanishes at J = 0), neo-Hookean stiffens.
  for (const double s : {0.9, 0.7, 0.5, 0.3})
    {
      Tensor<2, 3> F, P;
      for (unsigned int i = 0; i < 3; ++i)
        F[i][i] = std::cbrt(s);
      stvk.evaluate(F, P, nullptr);
      const double p_stvk = P[0][0];
      nh.evaluate(F, P, nullptr);
      deallog << "volume ratio " << s << ": P_11 St.Venant-Kirchhoff " << p_stvk
              << " Pa, neo-Hookean " << P[0][0] << " Pa" << std::endl;
    }
}
