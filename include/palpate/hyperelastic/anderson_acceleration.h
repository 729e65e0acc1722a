// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_anderson_acceleration_h
#define palpate_hyperelastic_anderson_acceleration_h

#include <vector>

namespace palpate
{
  /**
   * Anderson acceleration (Walker and Ni, SIAM J. Numer. Anal. 49, 2011)
   * of a fixed-point iteration x_{k+1} = x_k + f(x_k): here the
   * condensed path's quasi-Newton steps on factors of an older tangent,
   * which cut the residual by a fixed ratio per step (0.1-0.5 on the
   * liver: the tangent's change since the factors is a few smooth modes
   * the kept factors do not see).
   *
   * From the last depth differences of iterates (dX) and of steps (dF),
   * the step becomes f_k - (dX + dF) gamma, gamma minimising
   * |f_k - dF gamma|: the combination of the last iterates whose linear
   * model of the residual is smallest, which on a linear problem is
   * GMRES's iterate. It removes the slow modes in as many steps as there
   * are of them.
   *
   * The linear model holds while the map is one smooth map: the caller
   * resets it when the factors change (another preconditioner) or the
   * set of nodes in contact does (another branch of the contact's
   * piecewise-smooth map).
   */
  class AndersonAcceleration
  {
  public:
    /** @p depth differences kept (0: no acceleration). */
    explicit AndersonAcceleration(unsigned int depth = 0);

    /** Forget the history: the next step is taken as it is. */
    void
    reset();

    /**
     * Record the iterate @p x and its step @p f, and turn @p f into the
     * accelerated step. False (and @p f unchanged) while there is no
     * history to combine.
     */
    bool
    accelerate(const std::vector<double> &x, std::vector<double> &f);

    unsigned int
    depth() const;

  private:
    unsigned int                     max_depth;
    bool                             has_previous = false;
    std::vector<double>              x_previous, f_previous;
    std::vector<std::vector<double>> dX, dF, Q;
    std::vector<double>              R, gamma;
  };
} // namespace palpate

#endif
