#include "matching/views/retrieval.h"

#include <algorithm>
#include <tuple>

#include "models/errors.h"

namespace linetrack {

bool RetrievalOptions::Check(std::string* why) const {
  if (max_views < 1 || max_view_tokens < 1 || min_matched_tokens < 1 ||
      !std::isfinite(min_token_llr) || !(heading_window > 0.0)) {
    *why =
        "retrieval options: max_views, max_view_tokens, min_matched_tokens >= 1, heading_window "
        "> 0";
    return false;
  }
  return true;
}

std::vector<Token> ImageTokens(const std::vector<Segment2>& lines, const ViewDatabase& db) {
  return ComputeTokens(lines, db.equalisation, db.token_options);
}

namespace {

// The view's tokens of its longest segments, at most `count`.
std::vector<const Token*> LongestTokens(const ViewDatabase& db, int view, int count) {
  std::vector<const Token*> tokens;
  for (const Token& t : db.tokens[view])
    tokens.push_back(&t);
  const std::vector<ViewSegment>& segments = db.views[view].segments;
  const size_t n = std::min(tokens.size(), static_cast<size_t>(count));
  std::partial_sort(
      tokens.begin(), tokens.begin() + n, tokens.end(), [&](const Token* a, const Token* b) {
        return segments[a->segment].image.Length() > segments[b->segment].image.Length();
      });
  tokens.resize(n);
  return tokens;
}

}  // namespace

RetrievedView MatchView(const std::vector<Token>& image_tokens, const ViewDatabase& db, int view,
                        const RetrievalOptions& options) {
  RetrievedView out;
  out.view = view;
  const std::vector<const Token*> stored = LongestTokens(db, view, options.max_view_tokens);
  std::vector<std::tuple<double, int, int>> candidates;  // (llr, stored token, image token)
  for (size_t t = 0; t < stored.size(); ++t) {
    for (size_t p = 0; p < image_tokens.size(); ++p) {
      const double llr = TokenLogLikelihoodRatio(*stored[t], image_tokens[p], db.token_options);
      if (llr >= options.min_token_llr) {
        candidates.emplace_back(llr, static_cast<int>(t), static_cast<int>(p));
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const auto& a, const auto& b) { return std::get<0>(a) > std::get<0>(b); });
  std::vector<bool> stored_used(stored.size(), false), image_used(image_tokens.size(), false);
  for (const auto& [llr, t, p] : candidates) {
    if (stored_used[t] || image_used[p]) continue;
    stored_used[t] = image_used[p] = true;
    const int segment = stored[t]->segment;
    out.pairs.push_back(
        {image_tokens[p].segment, db.views[view].segments[segment].line_id, segment, llr});
    out.score += llr;
  }
  out.matched_tokens = static_cast<int>(out.pairs.size());
  return out;
}

std::vector<RetrievedView> RetrieveViews(const std::vector<Segment2>& lines, const ViewDatabase& db,
                                         const RetrievalOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(why);
  if (db.tokens.size() != db.views.size()) throw InputError("view database: tokens not computed");
  const std::vector<Token> image_tokens = ImageTokens(lines, db);
  std::vector<RetrievedView> ranked;
  for (size_t v = 0; v < db.views.size(); ++v) {
    const double heading = db.views[v].pose.heading;
    if (!options.headings.empty() &&
        std::none_of(options.headings.begin(), options.headings.end(), [&](double h) {
          return std::abs(WrapAngle(h - heading)) <= options.heading_window;
        })) {
      continue;
    }
    RetrievedView r = MatchView(image_tokens, db, static_cast<int>(v), options);
    if (r.matched_tokens >= options.min_matched_tokens) ranked.push_back(std::move(r));
  }
  std::stable_sort(
      ranked.begin(), ranked.end(),
      [](const RetrievedView& a, const RetrievedView& b) { return a.score > b.score; });
  if (static_cast<int>(ranked.size()) > options.max_views) ranked.resize(options.max_views);
  return ranked;
}

}  // namespace linetrack
