//! Built scenes kept for later units and renders, keyed by scene id. Concurrent loads of the
//! same scene build it once; the least recently used scene is dropped beyond the capacity (a
//! coordinator that still needs it gets NOT_FOUND and loads it again).

use std::collections::HashMap;
use std::future::Future;
use std::sync::{Arc, Mutex};

use tokio::sync::OnceCell;

type Slot<T> = Arc<OnceCell<Arc<T>>>;

/// Holds scenes of type `T` (the worker's built scene; generic so the policy is testable).
pub struct SceneCache<T> {
    capacity: usize,
    slots: Mutex<Slots<T>>,
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

impl<T> SceneCache<T> {
    pub fn new(capacity: usize) -> Self {
        Self {
            capacity: capacity.max(1),
            slots: Mutex::new(Slots {
                map: HashMap::new(),
                clock: 0,
            }),
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
                    self.evict(&mut slots, id);
                    slot
                }
            }
        };
        let mut built = false;
        let scene = slot
            .get_or_try_init(|| async {
                built = true;
                build().await.map(Arc::new)
            })
            .await?;
        Ok((scene.clone(), built))
    }

    fn evict(&self, slots: &mut Slots<T>, keep: &str) {
        while slots.map.len() > self.capacity {
            let oldest = slots
                .map
                .iter()
                .filter(|(id, _)| id.as_str() != keep)
                .min_by_key(|(_, (_, used))| *used)
                .map(|(id, _)| id.clone())
                .expect("more than one scene");
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
}
