#include "eval/gap_shape_choice.hpp"

#include <algorithm>

#include "eval/gap_effect_shapes.hpp"
#include "eval/gap_shape_pool.hpp"

namespace imscal::eval {
namespace {

// Relative margin within which the shape with fewer parameters wins the validation.
constexpr double kShapeParsimony = 0.01;

struct ShapeScore {
  double validation_sse = 0.0;
  std::size_t width = 0;  // parameters
};

// The index of the chosen shape among the scored ones (0 when none was scored).
std::size_t choose(const std::vector<ShapeScore>& scores) {
  if (scores.empty()) return 0;
  double best = scores.front().validation_sse;
  for (const ShapeScore& s : scores) best = std::min(best, s.validation_sse);
  const double margin = best * (1.0 + kShapeParsimony);
  std::size_t chosen = 0;
  for (std::size_t i = 0; i < scores.size(); ++i) {
    const ShapeScore &a = scores[i], &c = scores[chosen];
    if (a.validation_sse > margin) continue;
    if (c.validation_sse > margin || a.width < c.width ||
        (a.width == c.width && a.validation_sse < c.validation_sse))
      chosen = i;
  }
  return chosen;
}

ShapeScore score_of(const CandidateShape& shape, std::size_t joint, const GapSignals& s,
                    const TrainingFolds& folds) {
  // Within the shape's physical bound on its own joint, as its final fit (eval/gap_candidates.cpp).
  const ValidationLevel level{joint, &shape.level_signal, shape.level_lower};
  return {cross_validation_sse(shape.columns, s.gap_rad, folds, level),
          shape.parameter_names.size()};
}

// The chosen shape of an effect whose shapes are drawn from pools (EffectDefinition::shape_pools).
std::optional<CandidateShape> chosen_pooled_shape(const EffectDefinition& effect,
                                                  const ShapeContext& context, const GapSignals& s,
                                                  const TrainingFolds& folds) {
  const std::vector<ShapePool> pools = effect.shape_pools(context);
  std::size_t count = 0;
  for (const ShapePool& pool : pools) count += pool.shapes.size();
  if (count == 0) return std::nullopt;
  std::vector<ShapeScore> scores;
  if (count > 1 && folds.usable())
    for (const ShapePool& pool : pools) {
      const std::vector<double> sse = pooled_cross_validation_sse(pool, s.gap_rad, folds);
      for (std::size_t i = 0; i < sse.size(); ++i)
        scores.push_back({sse[i], pool.shapes[i].parameter_names.size()});
    }
  std::size_t chosen = choose(scores);
  for (const ShapePool& pool : pools) {
    if (chosen < pool.shapes.size()) return shape_from_pool(pool, chosen);
    chosen -= pool.shapes.size();
  }
  return std::nullopt;  // not reached: chosen < count
}

}  // namespace

std::optional<CandidateShape> chosen_shape(EffectKind kind, const GapSignals& s, std::size_t joint,
                                           const std::vector<bool>& training,
                                           const TrainingFolds& folds) {
  const EffectDefinition& effect = effect_definition(kind);
  const ShapeContext context(s, joint, &training);
  if (effect.shape_pools) return chosen_pooled_shape(effect, context, s, folds);
  std::vector<ShapeScore> scores;
  if (!effect.shape_at) {
    std::vector<CandidateShape> shapes = effect.shapes(context);
    if (shapes.empty()) return std::nullopt;
    if (shapes.size() > 1 && folds.usable())
      for (const CandidateShape& shape : shapes) scores.push_back(score_of(shape, joint, s, folds));
    return std::move(shapes[choose(scores)]);
  }
  const std::size_t count = effect.shape_count(context);
  if (count == 0) return std::nullopt;
  if (count > 1 && folds.usable())
    for (std::size_t i = 0; i < count; ++i)
      scores.push_back(score_of(effect.shape_at(context, i), joint, s, folds));
  return effect.shape_at(context, choose(scores));
}

}  // namespace imscal::eval
