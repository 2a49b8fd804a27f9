// One dynamic_reconfigure set-up for every nodelet and layer: the server with the recursive mutex
// it takes, bound to the owner's callback, and torn down before the owner's state goes.
#pragma once

#include <dynamic_reconfigure/server.h>
#include <ros/node_handle.h>

#include <boost/thread/recursive_mutex.hpp>
#include <cstdint>
#include <memory>

namespace downstream_perception {

/// The server of one dynamic_reconfigure ConfigT on a node handle's namespace.
///
/// The server calls the callback once at start() with the parameter server's values, then on
/// every change. What the callback leaves in the config it is given is what the server keeps
/// and rqt_reconfigure shows: a callback that refuses a value writes the value in use back into
/// it (the "revert rejected values" rule every owner follows).
template <class ConfigT>
class ReconfigureHost {
 public:
  ReconfigureHost() = default;
  ReconfigureHost(const ReconfigureHost&) = delete;
  ReconfigureHost& operator=(const ReconfigureHost&) = delete;

  /// Serves ConfigT on `nh`'s namespace into owner->*callback (called at once, here).
  template <class Owner>
  void start(const ros::NodeHandle& nh, Owner* owner,
             void (Owner::*callback)(ConfigT&, std::uint32_t)) {
    server_ = std::make_unique<Server>(mutex_, nh);
    server_->setCallback([owner, callback](ConfigT& config, std::uint32_t level) {
      (owner->*callback)(config, level);
    });
  }

  /// No more callbacks (call before the state the callback touches goes away).
  void stop() { server_.reset(); }

 private:
  using Server = dynamic_reconfigure::Server<ConfigT>;
  boost::recursive_mutex mutex_;  ///< declared first: outlives the server that locks it
  std::unique_ptr<Server> server_;
};

}  // namespace downstream_perception
