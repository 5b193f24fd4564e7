//! The oracle's privileged access, as an explicit seam.
//!
//! An observation made by a running trial may carry that trial, for oracle-type systems only
//! (planners with the true simulator, expert demonstrators; see `Observation::trial`). The
//! observation sits below the trial (the trial makes observations and hands them to systems),
//! so it must not name the trial's type: it holds a [`PrivilegedView`] instead, an opaque,
//! type-erased reference that the trial fills in (`Observation::with_trial`, in `trial`) and
//! that `Observation::trial` (also in `trial`) reads back as the trial. Nothing else can make
//! or read one, so this is the one way privileged state reaches a system.

use std::any::Any;

/// An opaque reference to the privileged state an observation was made from (the running
/// trial). Copying it copies the reference.
#[derive(Clone, Copy)]
pub(crate) struct PrivilegedView<'a> {
    source: &'a (dyn Any + Send + Sync),
}

impl<'a> PrivilegedView<'a> {
    /// A view of `source` (the trial, when it makes an observation of itself).
    pub(crate) fn new<T: Any + Send + Sync>(source: &'a T) -> Self {
        PrivilegedView { source }
    }

    /// The state viewed, if it is a `T` (the trial, for `Observation::trial`).
    pub(crate) fn get<T: Any>(&self) -> Option<&'a T> {
        self.source.downcast_ref::<T>()
    }
}
