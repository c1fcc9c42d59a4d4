//! Unidirectional path tracing with next-event estimation and MIS.
