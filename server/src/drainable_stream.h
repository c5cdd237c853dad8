// A long-lived streaming call (DistanceStream, SceneStream) that the service ends when it
// starts draining. Private to the server.
#pragma once

#include <atomic>

namespace inscribe::server {

// Reference-counted: gRPC holds one reference (released in the reactor's OnDone), and the
// service takes one for each Drain call it makes outside its lock.
class DrainableStream {
 public:
  // End now when waiting for the client's next message, else after the current one, with
  // UNAVAILABLE. Thread-safe.
  virtual void Drain() = 0;

  void Ref() { refs_.fetch_add(1); }
  void Unref() {
    if (refs_.fetch_sub(1) == 1) delete this;
  }

 protected:
  virtual ~DrainableStream() = default;

 private:
  std::atomic<int> refs_{1};
};

}  // namespace inscribe::server
