#pragma once
// One function per part of the module; module.cpp calls them in order.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>

#include <tbb/task_arena.h>

namespace clothcd::python {

void bind_mesh(pybind11::module_& m);
void bind_detect(pybind11::module_& m);
void bind_ccd(pybind11::module_& m);
void bind_cone(pybind11::module_& m);
void bind_sim(pybind11::module_& m);
void bind_view(pybind11::module_& m);

/// Runs work without the GIL, in an arena of `threads` workers (0: TBB's default, all cores).
class Workers {
 public:
  explicit Workers(int threads);
  [[nodiscard]] int threads() const { return threads_; }
  template <class F>
  auto run(F&& f) -> decltype(f()) {
    pybind11::gil_scoped_release release;
    // One call at a time per object: the detectors keep state between calls.
    const std::lock_guard lock(mutex_);
    if (arena_) return arena_->execute(std::forward<F>(f));
    return f();
  }

 private:
  int threads_ = 0;
  std::unique_ptr<tbb::task_arena> arena_;
  std::mutex mutex_;
};

}  // namespace clothcd::python
