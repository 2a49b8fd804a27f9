// Work shared between the calling thread and one helper thread, for the few loops that pay for a
// second core (a dense scan's clearing walk).
//
// Why not a thread per call, or a pool that the caller waits on: on a loaded machine (a robot's
// CPU runs many nodes) the second thread may not be scheduled for milliseconds, and a caller that
// joins it waits that long: a 1.4 ms scan walk measured 3.7 ms with std::thread on this project's
// 2-core machine while another build ran. Here the caller claims the pieces of work one by one
// from a shared counter, and the helper claims from the same counter when it gets to run; the
// caller waits only for pieces the helper has already started. With no free core the caller
// simply does all pieces itself, at one thread's cost plus the wake-up of the helper (~5 us).
#pragma once

#include <functional>

namespace downstream_perception {

/// Runs task(i) for every i in [0, count) exactly once, on the calling thread and (when it is free
/// and gets a core) the process's helper thread; returns when every call has returned. Calls with
/// different i must touch disjoint data. `task` must not throw. count <= 1, or a machine with one
/// core, runs everything on the calling thread.
void runShared(int count, const std::function<void(int)>& task);

}  // namespace downstream_perception
