// Bakers that share one bake's directions: each bakes the directions
// k = index (mod count) and, at each radiance refresh, all of them add their
// accumulators together so every one reads the same light maps. The engine
// knows no transport; headless/cli/mpi_share.cpp implements this over MPI.
//
// The schedule in rounds: round j holds directions j*count .. j*count+count-1,
// one per baker. Each round adds a bounce at most (the refresh that lets the
// next bundles see the last round's light comes after a round), so the
// history ramp and the refresh schedule run on rounds; with count 1 a round
// is a direction and the bake is byte for byte a bake of its own.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace bb {

class DirectionShare {
public:
    virtual ~DirectionShare() = default;
    virtual int index() const = 0;  // 0 .. count-1; 0 writes the outputs and checkpoints
    virtual int count() const = 0;
    // Element-wise sum over every baker, in place. Every baker receives the
    // same bits, and the same count sums in the same order on every run.
    virtual void sum(float* values, size_t n) = 0;
    // Every baker's text, in index order, on every baker.
    virtual std::vector<std::string> gather(const std::string& text) = 0;
    // Returns when every baker has called it.
    virtual void barrier() = 0;
    // Seconds spent in sum/gather/barrier so far: waiting for the others, then moving bytes.
    virtual double secondsWaiting() const = 0;
    virtual double secondsTransferring() const = 0;
};

}  // namespace bb
