#pragma once
/// \file progress.h
/// Progress and cancellation through VCG's callback (a plain function pointer): a stage's
/// 0..100 mapped into a range of the caller's bar, and the host's "stop" turned into an
/// exception thrown from the next progress report. Also the stages' wall-clock timing.

#include <wrap/callback.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace ib {

/// The progress callback returned false: the host asked to stop. Nothing is returned.
class Cancelled : public std::runtime_error
{
public:
    Cancelled() : std::runtime_error("cancelled") {}
};

/// Turns a callback's false ("stop") into a Cancelled exception, thrown from the call, so each
/// stage stops at its next progress report without checking. Like ProgressRange, the target
/// lives in thread-local state; stages report from the calling thread only (ParallelFor
/// rethrows there once its threads are done).
class Cancellation
{
public:
    /// A callback forwarding to `target`, or null when target is null.
    static vcg::CallBackPos* Watch(vcg::CallBackPos* target)
    {
        target_ = target;
        return target ? &Forward : nullptr;
    }

private:
    static bool Forward(const int pos, const char* what)
    {
        if (!target_(pos, what))
            throw Cancelled();
        return true;
    }
    static inline thread_local vcg::CallBackPos* target_ = nullptr;
};

/// Forwards a stage's own 0..100 progress into a range of the caller's callback. VCG's
/// callback is a plain function pointer, so the range lives in thread-local state; stages
/// report from the calling thread only.
class ProgressRange
{
public:
    /// A callback mapping 0..100 into [lo, hi] of `target`, or null when target is null.
    static vcg::CallBackPos* Into(vcg::CallBackPos* target, int lo, int hi)
    {
        target_ = target;
        lo_ = lo;
        hi_ = hi;
        return target ? &Forward : nullptr;
    }

private:
    static bool Forward(const int pos, const char* what)
    {
        return target_(lo_ + (hi_ - lo_) * std::clamp(pos, 0, 100) / 100, what);
    }
    static inline thread_local vcg::CallBackPos* target_ = nullptr;
    static inline thread_local int lo_ = 0, hi_ = 100;
};

/// Wall-clock seconds of consecutive stages: each Lap() is the time since the previous one
/// (or since construction), and starts the next.
class Stopwatch
{
public:
    double Lap()
    {
        const Clock::time_point now = Clock::now();
        const double seconds = std::chrono::duration<double>(now - start_).count();
        start_ = now;
        return seconds;
    }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point start_ = Clock::now();
};

} // namespace ib
