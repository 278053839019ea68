// `mpirun -np N bundlebake bake ...` (or srun, or any MPI launcher): the
// rank's share of the directions (bake/direction_share.h) over MPI.
//
// MPI starts only when a launcher started this process (its environment says
// so), so a plain run never touches MPI; a build without MPI refuses to run
// as one of several ranks instead of baking N copies into one directory.
#pragma once

#include <memory>

#include "bake/direction_share.h"
#include "core/status.h"

namespace bb::cli {

class MpiShare : public DirectionShare {
public:
    // Null when this process was not launched by an MPI launcher. MPI ends
    // (MPI_Finalize) with the last reference.
    static Expected<std::shared_ptr<MpiShare>> startIfLaunched();
    ~MpiShare() override;
    // Ends every rank's process with `code` (MPI_Abort): a rank that fails
    // takes the job down at once instead of leaving the others in a sum.
    [[noreturn]] void abortAll(int code);

    int index() const override { return rank_; }
    int count() const override { return size_; }
    void sum(float* values, size_t n) override;
    std::vector<std::string> gather(const std::string& text) override;
    void barrier() override;
    double secondsWaiting() const override { return waiting_; }
    double secondsTransferring() const override { return transferring_; }

private:
    MpiShare(int rank, int size) : rank_(rank), size_(size) {}
    int rank_ = 0, size_ = 1;
    double waiting_ = 0, transferring_ = 0;
};

}  // namespace bb::cli
