// Retrieval of the key views most like an image by token matching (seed 002, section 4): for
// each token of a stored view the image segment maximising p(P | T) (eq. 15), one-to-one; a
// view's score is the summed log-likelihood ratio of its matched tokens. Each matched token
// transfers its segment's line id to the image segment: the 2D-3D pairs that verification
// then accepts or rejects. docs/views.md.
#pragma once

#include <string>
#include <vector>

#include "matching/views/key_view.h"
#include "matching/views/tokens.h"

namespace linetrack {

struct RetrievalOptions {
  int max_views = 10;          // ranked views returned
  int max_view_tokens = 16;    // tokens of a stored view matched: its longest segments
  double min_token_llr = 3.0;  // a token matches an image segment with at least this ratio
  int min_matched_tokens = 2;  // a view needs at least this many matched tokens to rank
  // When not empty, only the views whose heading is within heading_window of one of these
  // (radians), e.g. the candidates of EstimateHeading: a prior that cuts the search.
  std::vector<double> headings;
  double heading_window = DegToRad(20.0);

  bool Check(std::string* why) const;
};

// An image segment given the line id of a stored view's segment.
struct TransferredPair {
  int line = -1;          // index of the image segment
  int line_id = -1;       // the 3D line (model edge id), -1 when the stored segment has none
  int view_segment = -1;  // index of the segment in the stored view
  double llr = 0.0;       // the token match's log-likelihood ratio
};

struct RetrievedView {
  int view = -1;       // index into ViewDatabase::views
  double score = 0.0;  // summed log-likelihood ratio of the matched tokens
  int matched_tokens = 0;
  std::vector<TransferredPair> pairs;  // the token matches, best first
};

// The tokens of an image's segments (undistorted pixels) in the database's equalisation.
std::vector<Token> ImageTokens(const std::vector<Segment2>& lines, const ViewDatabase& db);

// One stored view against the image tokens: matches greedy by ratio, one-to-one.
RetrievedView MatchView(const std::vector<Token>& image_tokens, const ViewDatabase& db, int view,
                        const RetrievalOptions& options);

// The views with at least min_matched_tokens matches, by score, at most max_views. Throws
// InputError when the options are invalid or the database has no tokens.
std::vector<RetrievedView> RetrieveViews(const std::vector<Segment2>& lines, const ViewDatabase& db,
                                         const RetrievalOptions& options);

}  // namespace linetrack
