#pragma once
/// Large values handed from one thread to others without copying them: the producer takes an
/// object from the pool, fills it, and shares it (std::shared_ptr); when the last holder lets go,
/// the object goes back to the pool with its storage, and a later take() hands it out again to be
/// overwritten. An object is never handed out while anyone still holds it, so a holder may read it
/// for as long as it likes while the producer fills others.
///
/// Thread-safe. The return to the pool and take() synchronise on one mutex, so everything a holder
/// did with an object happens before the next taker's writes (no reliance on use_count()).
/// Holders may outlive the pool: an object let go after the pool is gone is deleted.
/// After warm-up (as many objects as are ever held at once) nothing is allocated by the pool, and
/// nothing by T if T reuses its storage (e.g. cv::Mat::create with an unchanged size).
#include <memory>
#include <mutex>
#include <vector>

namespace spidar::core {

template <typename T>
class RecyclingPool {
 public:
  RecyclingPool() : state_(std::make_shared<State>()) {}

  /// An object nobody holds (a recycled one, with whatever its last holder left in it, or a new
  /// default-constructed one if every object is held).
  std::shared_ptr<T> take() {
    std::unique_ptr<T> obj;
    {
      std::lock_guard lock(state_->mutex);
      if (!state_->free.empty()) {
        obj = std::move(state_->free.back());
        state_->free.pop_back();
      } else {
        ++state_->created;
      }
    }
    if (!obj) obj = std::make_unique<T>();
    std::weak_ptr<State> home = state_;
    return std::shared_ptr<T>(obj.release(), [home](T* p) {
      std::unique_ptr<T> back(p);
      if (auto s = home.lock()) {
        std::lock_guard lock(s->mutex);
        s->free.push_back(std::move(back));
      }  // else the pool is gone: the object is deleted here
    });
  }

  /// Objects made so far (held or free).
  std::size_t created() const {
    std::lock_guard lock(state_->mutex);
    return state_->created;
  }
  /// Objects in the pool, held by nobody.
  std::size_t free() const {
    std::lock_guard lock(state_->mutex);
    return state_->free.size();
  }

 private:
  struct State {
    mutable std::mutex mutex;
    std::vector<std::unique_ptr<T>> free;
    std::size_t created = 0;
  };
  std::shared_ptr<State> state_;
};

}  // namespace spidar::core
