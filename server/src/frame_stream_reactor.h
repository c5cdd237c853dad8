// The lifecycle every frame stream shares (DistanceStream, SceneStream): one long-lived
// bidirectional call, one reply per request, in order. One frame is in the reactor at a time
// (read, admit, compute, write, read the next), so frames can never be reordered, nothing
// else touches the frame while it runs, and a slow client slows only itself. A frame is
// computed where the FrameDispatcher says (frame_dispatch.h). Private to the server.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <new>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "admission.h"
#include "drainable_stream.h"
#include "frame_dispatch.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "service_checks.h"
#include "service_parts.h"

namespace inscribe::server {

// The state machine, the service's bookkeeping (active calls, the drainable streams, the
// call record and its observer: Admission), drain and cancellation, timing and the cost model.
// A stream derives from it and supplies its hooks: Admit, Work and Answer, and where it needs
// them InFrame, Timed, FrameEnded and Closed.
//
// States: kStarting (before the first read), kReading (a read is pending; nothing else),
// kBusy (a frame is being computed or its reply written), kFinished (Finish was called).
// Transitions happen under mutex_, and Finish, StartRead and StartWrite are called under it,
// so a drain can never finish a stream between a state change and the read it announces.
template <typename Request, typename Reply>
class FrameStreamReactor : public grpc::ServerBidiReactor<Request, Reply>, public DrainableStream {
 public:
  // Admission::Enter under the stream's lock (a drain that starts meanwhile is either seen
  // there or finds the stream reading); a refused stream ends before any read.
  void Start() {
    parts_.admission.CallStarted();
    parts_.admission.AddStream(this);
    std::lock_guard<std::mutex> lock(mutex_);
    if (absl::Status entered = parts_.admission.Enter(*context_); !entered.ok()) {
      FinishLocked(entered);
      return;
    }
    state_ = State::kReading;
    this->StartRead(&request_);
  }

  // The service is draining: end now when waiting for a frame, else after the current one's
  // reply has been written.
  void Drain() final {
    std::lock_guard<std::mutex> lock(mutex_);
    draining_ = true;
    if (state_ == State::kReading) {
      FinishLocked(absl::UnavailableError("server is shutting down; reconnect to another"));
    }
  }

  void OnReadDone(bool ok) final {
    const ServiceClock::time_point arrived = ServiceClock::now();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (state_ == State::kFinished) return;
      if (!ok) {
        // The client half-closed (done sending) or the call was cancelled; either way every
        // frame read has been answered.
        FinishLocked(absl::OkStatus());
        return;
      }
      if (absl::Status s = Admit(); !s.ok()) {
        FinishLocked(InFrame(s));
        return;
      }
      // kBusy: a drain now waits for this frame's reply, and nothing else touches the frame.
      state_ = State::kBusy;
    }
    const FrameWork work = Work();
    // After a true return the reply may be written and the next frame running: no member may
    // be touched here.
    if (!parts_.frames.Run(work, cost_.Estimate(work.items),
                           [this, arrived, items = work.items](FramePlace place) {
                             RunFrame(arrived, place, items);
                           })) {
      std::lock_guard<std::mutex> lock(mutex_);
      FinishLocked(parts_.admission.QueueFullError());
    }
  }

  void OnWriteDone(bool ok) final {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state_ == State::kFinished) return;
    if (!ok) {
      FinishLocked(absl::CancelledError("client went away"));
      return;
    }
    FrameEnded();
    if (draining_) {
      FinishLocked(absl::UnavailableError("server is shutting down; reconnect to another"));
      return;
    }
    state_ = State::kReading;
    this->StartRead(&request_);
  }

  void OnCancel() final { cancelled_.store(true); }

  void OnDone() final {
    parts_.admission.RemoveStream(this);
    record_.status = final_status_;
    parts_.admission.Observe(record_);
    Closed();
    parts_.admission.CallEnded();
    Unref();
  }

 protected:
  // `method`: the RPC's name, for the call record and messages.
  FrameStreamReactor(const ServiceParts& parts, grpc::CallbackServerContext* context,
                     const char* method)
      : parts_(parts), context_(context) {
    record_.method = method;
    record_.peer = context->peer();
  }
  ~FrameStreamReactor() override = default;

  // The hooks, in the order a frame meets them. Admit, Work and Answer see the frame alone:
  // gRPC callbacks and the frame's job never overlap.

  // The O(1) checks of request() on the gRPC thread, under the stream's lock, with any memory
  // reservation the frame or the stream needs; an error ends the stream (through InFrame).
  virtual absl::Status Admit() = 0;
  // What the dispatcher needs to know of the admitted frame (FrameWork); items is the unit of
  // this stream's cost model. Outside the lock, on the gRPC thread.
  virtual FrameWork Work() = 0;
  // The frame's answer into reply(), where the dispatcher put it (`place`); an error ends the
  // stream (through InFrame). May throw std::bad_alloc.
  virtual absl::Status Answer(FramePlace place) = 0;
  // The status a failed frame ends the stream with (refused by Admit; failed, out of memory or
  // cancelled while answered); by default `status` itself.
  virtual absl::Status InFrame(const absl::Status& status) const { return status; }
  // The frame was answered in `seconds` of run time; its reply is written next.
  virtual void Timed(double /*seconds*/) {}
  // The frame is over (its reply written, or the stream finished): release what it held.
  // Under the stream's lock.
  virtual void FrameEnded() {}
  // The call is done and observed: release what the stream held for its life.
  virtual void Closed() {}

  const ServiceParts& parts() const { return parts_; }
  Request& request() { return request_; }
  const Request& request() const { return request_; }
  Reply& reply() { return reply_; }
  CallRecord& record() { return record_; }
  // Set once gRPC reports the call cancelled; frames' long loops poll it.
  const std::atomic<bool>& cancelled() const { return cancelled_; }

 private:
  enum class State { kStarting, kReading, kBusy, kFinished };

  void FinishLocked(const absl::Status& status) {
    FrameEnded();
    state_ = State::kFinished;
    final_status_ = status;
    this->Finish(wire::ToGrpcStatus(status));
  }

  // Where the dispatcher put it (inline on the gRPC thread, or on the pool): answers the frame
  // of `items` work items, then writes its reply (or ends the stream).
  void RunFrame(ServiceClock::time_point arrived, FramePlace place, std::int64_t items) {
    const ServiceClock::time_point started = ServiceClock::now();
    record_.queued_seconds += std::chrono::duration<double>(started - arrived).count();
    absl::Status status;
    try {
      status = Answer(place);
    } catch (const std::bad_alloc&) {
      status = absl::ResourceExhaustedError(
          absl::StrCat("server ran out of memory in ", record_.method));
    }
    if (status.ok() && cancelled_.load()) status = absl::CancelledError("client went away");
    const double seconds = SecondsSince(started);
    record_.run_seconds += seconds;
    if (status.ok()) {
      Timed(seconds);
      cost_.Record(items, seconds);
      ++record_.frames;
      if (place == FramePlace::kInline) ++record_.inline_frames;
    }
    // On the pool this is no gRPC reaction, so once Finish is called gRPC may run OnDone, and
    // delete the stream, on another thread before the lock below is released: the frame holds
    // a reference until it is done with the stream (TSan saw the mutex unlocked after it was
    // freed in StreamDispatchTest.DrainAndCancelInTheMiddleOfInlineFrames).
    this->Ref();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (status.ok()) {
        this->StartWrite(&reply_);
      } else {
        FinishLocked(InFrame(status));
      }
    }
    this->Unref();
  }

  const ServiceParts parts_;
  grpc::CallbackServerContext* const context_;
  std::atomic<bool> cancelled_{false};

  std::mutex mutex_;
  State state_ = State::kStarting;  // guarded by mutex_
  bool draining_ = false;           // guarded by mutex_
  absl::Status final_status_;       // set once, by FinishLocked

  // Touched by one thread at a time: gRPC callbacks and the frame's job never overlap.
  Request request_;
  Reply reply_;
  FrameCostModel cost_;  // this stream's seconds per work item
  CallRecord record_;
};

}  // namespace inscribe::server
