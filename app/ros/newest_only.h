// The node's image slot: a one-place queue that keeps the newest item. Putting one while another
// waits replaces it (the older is dropped, and the caller counts it), so that a consumer slower
// than the stream processes the newest image next and never lags behind. Not synchronised: the
// node holds its mutex around it.
#pragma once

#include <optional>
#include <utility>

namespace linetrack::app {

template <typename T>
class NewestOnly {
 public:
  // Stores `item`; true when an older one was waiting and is dropped.
  bool Put(T item) {
    const bool dropped = item_.has_value();
    item_ = std::move(item);
    return dropped;
  }

  // The waiting item, if any, leaving the slot empty.
  std::optional<T> Take() {
    std::optional<T> out;
    out.swap(item_);
    return out;
  }

  bool waiting() const { return item_.has_value(); }

 private:
  std::optional<T> item_;
};

}  // namespace linetrack::app
