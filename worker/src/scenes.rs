//! Built scenes kept for later units and renders, keyed by scene id. Concurrent loads of the
//! same scene build it once, and builds of different scenes run one at a time (a build can take
//! a lot of memory). Beyond the capacity the least recently used scene is dropped once a new one
//! is built (a coordinator that still needs it gets NOT_FOUND and loads it again), but never a
//! scene that units are rendering or that is being built, and a failed build drops nothing.

use std::collections::HashMap;
use std::future::Future;
use std::sync::{Arc, Mutex};

use tokio::sync::{OnceCell, Semaphore};

type Slot<T> = Arc<OnceCell<Arc<T>>>;

/// Holds scenes of type `T` (the worker's built scene; generic so the policy is testable).
pub struct SceneCache<T> {
    capacity: usize,
    slots: Mutex<Slots<T>>,
    builds: Semaphore,
}

struct Slots<T> {
    map: HashMap<String, (Slot<T>, u64)>,
    clock: u64,
}

impl<T> Slots<T> {
    fn touch(&mut self, id: &str) -> Option<Slot<T>> {
        self.clock += 1;
        let clock = self.clock;
        self.map.get_mut(id).map(|(slot, used)| {
            *used = clock;
            slot.clone()
        })
    }
}

/// Whether a slot must stay: it is being built, or someone besides the cache holds its scene
/// (a unit rendering it).
fn pinned<T>(slot: &Slot<T>) -> bool {
    slot.get().is_none_or(|scene| Arc::strong_count(scene) > 1)
}

impl<T> SceneCache<T> {
    pub fn new(capacity: usize) -> Self {
        Self {
            capacity: capacity.max(1),
            slots: Mutex::new(Slots {
                map: HashMap::new(),
                clock: 0,
            }),
            builds: Semaphore::new(1),
        }
    }

    /// A built scene, if held.
    pub fn get(&self, id: &str) -> Option<Arc<T>> {
        self.slots.lock().unwrap().touch(id)?.get().cloned()
    }

    /// Scenes built and held.
    pub fn len(&self) -> usize {
        let slots = self.slots.lock().unwrap();
        slots.map.values().filter(|(s, _)| s.initialized()).count()
    }

    /// The scene `id`, built by `build` unless it is held or being built; also says whether
    /// this call built it. A failed build leaves nothing behind, so a later call tries again.
    pub async fn get_or_build<F, Fut, E>(&self, id: &str, build: F) -> Result<(Arc<T>, bool), E>
    where
        F: FnOnce() -> Fut,
        Fut: Future<Output = Result<T, E>>,
    {
        let slot = {
            let mut slots = self.slots.lock().unwrap();
            match slots.touch(id) {
                Some(slot) => slot,
                None => {
                    let slot = Slot::<T>::default();
                    let clock = slots.clock;
                    slots.map.insert(id.to_string(), (slot.clone(), clock));
                    slot
                }
            }
        };
        let mut built = false;
        let scene = slot
            .get_or_try_init(|| async {
                let _one_build_at_a_time = self.builds.acquire().await.expect("never closed");
                built = true;
                build().await.map(Arc::new)
            })
            .await;
        let mut slots = self.slots.lock().unwrap();
        match scene {
            Ok(scene) => {
                let scene = scene.clone();
                self.evict(&mut slots, id);
                Ok((scene, built))
            }
            Err(error) => {
                let ours = slots
                    .map
                    .get(id)
                    .is_some_and(|(s, _)| Arc::ptr_eq(s, &slot) && !s.initialized());
                if ours {
                    slots.map.remove(id);
                }
                Err(error)
            }
        }
    }

    /// Drops the least recently used scenes that are not pinned until at most `capacity`
    /// remain, or only pinned ones and `keep`.
    fn evict(&self, slots: &mut Slots<T>, keep: &str) {
        while slots.map.len() > self.capacity {
            let oldest = slots
                .map
                .iter()
                .filter(|(id, (slot, _))| id.as_str() != keep && !pinned(slot))
                .min_by_key(|(_, (_, used))| *used)
                .map(|(id, _)| id.clone());
            let Some(oldest) = oldest else {
                return;
            };
            slots.map.remove(&oldest);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn builds_once_retries_failures_and_evicts_the_least_recently_used() {
        let cache = SceneCache::<u32>::new(2);
        let failed: Result<_, &str> = cache.get_or_build("a", || async { Err("boom") }).await;
        assert!(failed.is_err());
        assert!(cache.get("a").is_none());
        let (a, built) = cache
            .get_or_build("a", || async { Ok::<_, ()>(1) })
            .await
            .unwrap();
        assert!(built && *a == 1);
        let (a, built) = cache
            .get_or_build("a", || async { Ok::<_, ()>(99) })
            .await
            .unwrap();
        assert!(!built && *a == 1, "a held scene is not rebuilt");
        cache
            .get_or_build("b", || async { Ok::<_, ()>(2) })
            .await
            .unwrap();
        assert_eq!(cache.get("a").as_deref(), Some(&1));
        cache
            .get_or_build("c", || async { Ok::<_, ()>(3) })
            .await
            .unwrap();
        assert!(cache.get("b").is_none(), "b was the least recently used");
        assert_eq!(cache.get("a").as_deref(), Some(&1));
        assert_eq!(cache.len(), 2);
    }

    #[tokio::test]
    async fn scenes_in_use_stay_and_failed_builds_evict_nothing() {
        let cache = SceneCache::<u32>::new(1);
        let (a, _) = cache
            .get_or_build("a", || async { Ok::<_, ()>(1) })
            .await
            .unwrap();
        let failed: Result<_, &str> = cache.get_or_build("b", || async { Err("boom") }).await;
        assert!(failed.is_err());
        assert_eq!(
            cache.get("a").as_deref(),
            Some(&1),
            "a failed build evicts nothing"
        );
        cache
            .get_or_build("c", || async { Ok::<_, ()>(3) })
            .await
            .unwrap();
        assert_eq!(
            cache.get("a").as_deref(),
            Some(&1),
            "a scene a unit holds is not evicted"
        );
        drop(a);
        cache
            .get_or_build("d", || async { Ok::<_, ()>(4) })
            .await
            .unwrap();
        assert!(cache.get("a").is_none() && cache.get("c").is_none());
        assert_eq!(cache.len(), 1);
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn builds_run_one_at_a_time() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let cache = Arc::new(SceneCache::<usize>::new(8));
        let (running, most) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
        let loads = (0..4).map(|i| {
            let (cache, running, most) = (cache.clone(), running.clone(), most.clone());
            tokio::spawn(async move {
                cache
                    .get_or_build(&i.to_string(), || async move {
                        let now = running.fetch_add(1, Ordering::SeqCst) + 1;
                        most.fetch_max(now, Ordering::SeqCst);
                        tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                        running.fetch_sub(1, Ordering::SeqCst);
                        Ok::<_, ()>(i)
                    })
                    .await
            })
        });
        for load in loads.collect::<Vec<_>>() {
            load.await.unwrap().unwrap();
        }
        assert_eq!(most.load(Ordering::SeqCst), 1);
        assert_eq!(cache.len(), 4);
    }
}
