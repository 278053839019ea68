#include "headless/mpi/mpi_share.h"

#include <algorithm>
#include <cstdlib>

#include "core/timer.h"

#ifdef BUNDLEBAKE_WITH_MPI
#include <mpi.h>
#endif

namespace bb::cli {
namespace {
// What Open MPI (mpirun), MPICH/Hydra and PMIx launchers (srun among them) set in each rank's environment.
bool launchedByMpi(int* declaredSize) {
    *declaredSize = 0;
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"})
        if (const char* v = std::getenv(name)) *declaredSize = std::max(*declaredSize, std::atoi(v));
    return *declaredSize > 0 || std::getenv("PMIX_RANK") != nullptr;
}
}  // namespace

#ifdef BUNDLEBAKE_WITH_MPI

Expected<std::shared_ptr<MpiShare>> MpiShare::startIfLaunched() {
    int declared = 0;
    if (!launchedByMpi(&declared)) return std::shared_ptr<MpiShare>();
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) MPI_Init(nullptr, nullptr);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    return std::shared_ptr<MpiShare>(new MpiShare(rank, size));
}

MpiShare::~MpiShare() { MPI_Finalize(); }

void MpiShare::abortAll(int code) {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);  // not reached
}

void MpiShare::barrier() {
    const auto t0 = Clock::now();
    MPI_Barrier(MPI_COMM_WORLD);
    waiting_ += secondsSince(t0);
}

void MpiShare::sum(float* values, size_t n) {
    barrier();  // the wait for the slowest rank, apart from the transfer
    const auto t0 = Clock::now();
    constexpr size_t CHUNK = size_t(1) << 26;  // MPI counts are int; 256 MiB a call
    for (size_t i = 0; i < n; i += CHUNK)
        MPI_Allreduce(MPI_IN_PLACE, values + i, int(std::min(CHUNK, n - i)), MPI_FLOAT, MPI_SUM, MPI_COMM_WORLD);
    transferring_ += secondsSince(t0);
}

std::vector<std::string> MpiShare::gather(const std::string& text) {
    const auto t0 = Clock::now();
    const int length = int(text.size());
    std::vector<int> lengths(static_cast<size_t>(size_), 0), offsets(static_cast<size_t>(size_), 0);
    MPI_Allgather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, MPI_COMM_WORLD);
    for (int r = 1; r < size_; ++r) offsets[size_t(r)] = offsets[size_t(r) - 1] + lengths[size_t(r) - 1];
    std::string all(size_t(offsets.back() + lengths.back()), '\0');
    MPI_Allgatherv(text.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
                   MPI_COMM_WORLD);
    std::vector<std::string> out;
    for (int r = 0; r < size_; ++r) out.push_back(all.substr(size_t(offsets[size_t(r)]), size_t(lengths[size_t(r)])));
    transferring_ += secondsSince(t0);
    return out;
}

#else  // built without MPI

Expected<std::shared_ptr<MpiShare>> MpiShare::startIfLaunched() {
    int declared = 0;
    if (!launchedByMpi(&declared) || declared == 1) return std::shared_ptr<MpiShare>();
    return Expected<std::shared_ptr<MpiShare>>::failure(
        "started by an MPI launcher, but this bundlebake was built without MPI (install libopenmpi-dev and rebuild)");
}

MpiShare::~MpiShare() = default;
void MpiShare::abortAll(int code) { std::exit(code); }
void MpiShare::barrier() {}
void MpiShare::sum(float*, size_t) {}
std::vector<std::string> MpiShare::gather(const std::string& text) { return {text}; }

#endif

}  // namespace bb::cli
