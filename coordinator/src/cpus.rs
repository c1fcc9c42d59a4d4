//! How many threads a render or a worker uses when `--threads` is not given: the CPUs this
//! process may use. `std::thread::available_parallelism` gives that figure: on Linux it is the
//! size of the sched affinity mask (`taskset`, Slurm's and Kubernetes' cpusets), lowered to the
//! cgroup v1 or v2 CPU quota when there is one (a container's `--cpus`, a pod's CPU limit).

/// `threads` if given, else the CPUs this process may use; logs where the figure came from.
pub fn threads_or_usable_cpus(threads: Option<usize>, what: &str) -> usize {
    if let Some(threads) = threads {
        return threads.max(1);
    }
    let cpus = usable_cpus();
    tracing::info!(
        "{what}: {cpus} thread(s), the CPUs this process may use (affinity mask and cgroup quota)"
    );
    cpus
}

/// The CPUs this process may use (one when the figure is unknown).
pub fn usable_cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
