// The time of impact's root finding, shared by the rigid bodies' paths
// (step_integrator.cc) and the links' joint paths (link_impacts.cc): a
// bracket of times with the gap above a target at one end and at or below
// it at the other, narrowed by regula falsi.
#ifndef RIGID_BODY_SIM_PHYSICS_DYNAMICS_TIME_OF_IMPACT_H_
#define RIGID_BODY_SIM_PHYSICS_DYNAMICS_TIME_OF_IMPACT_H_

namespace rigid_body_sim::physics {

// Bisection stops when the bracket is shorter than this fraction of the step.
constexpr double kTimeOfImpactTolerance = 1e-6;

// Times with gap(low) > target_gap >= gap(high).
struct ImpactBracket {
  double low = 0.0;       // s
  double gap_low = 0.0;   // m
  double high = -1.0;     // s; < 0 while no sample touched
  double gap_high = 0.0;  // m
};

// The gaps a narrowing aims at, m: the legal end must come within
// close_enough; each estimate aims at `aim` below it.
struct ImpactTarget {
  double target_gap = 0.0;  // the bracket's dividing gap
  double touching = 0.0;    // the touching band's top, above target_gap
};

// Regula falsi on gap(t) = aim, keeping the bracket gap(low) > target_gap >=
// gap(high) (Illinois: the end kept twice in a row has its value halved, so
// it converges superlinearly instead of creeping; Dowell and Jarratt, "A
// modified regula falsi method for computing the root of an equation",
// BIT 11, 1971). It ends when `low` is within a tenth of the touching band
// above target_gap, so the free flight is cut short by at most that much,
// or when the bracket is within kTimeOfImpactTolerance of dt, as plain
// bisection would. `gap_at(t)` is the gap at time t, m. Returns the
// narrowed bracket, whose legal end is `low`.
template <typename GapAt>
ImpactBracket NarrowImpactBracket(const GapAt& gap_at, const ImpactTarget& target, double dt,
                                  ImpactBracket bracket) {
  const double band = target.touching - target.target_gap;
  const double close_enough = target.target_gap + 0.1 * band;
  const double aim = target.target_gap + 0.05 * band;
  int kept_side = 0;  // -1: low was kept last time, +1: high
  double weight_low = 1.0;
  double weight_high = 1.0;
  while (bracket.gap_low > close_enough &&
         bracket.high - bracket.low > kTimeOfImpactTolerance * dt) {
    const double f_low = weight_low * (bracket.gap_low - aim);
    const double f_high = weight_high * (bracket.gap_high - aim);
    double t = bracket.low + (bracket.high - bracket.low) * f_low / (f_low - f_high);
    if (!(t > bracket.low && t < bracket.high)) t = 0.5 * (bracket.low + bracket.high);
    const double gap = gap_at(t);
    if (gap > target.target_gap) {
      bracket.low = t;
      bracket.gap_low = gap;
      weight_low = 1.0;
      weight_high = kept_side == 1 ? 0.5 * weight_high : 1.0;
      kept_side = 1;
    } else {
      bracket.high = t;
      bracket.gap_high = gap;
      weight_high = 1.0;
      weight_low = kept_side == -1 ? 0.5 * weight_low : 1.0;
      kept_side = -1;
    }
  }
  return bracket;
}

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_DYNAMICS_TIME_OF_IMPACT_H_
