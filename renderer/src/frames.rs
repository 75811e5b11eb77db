//! Frames in flight: a ring of N frame slots (command buffer, fence, timestamp pool — the
//! `FrameRecorder` — and, in each view, the slot's uniforms, counters and read-backs). Frame `f`
//! uses slot `f % N`; submitting it first waits for frame `f − N`, the slot's previous frame, so
//! the CPU records frame `f` while the GPU still runs up to N − 1 earlier ones. A frame's timings,
//! counters and read-backs are read from its slot once its fence signalled, until the slot comes
//! round again.
//!
//! Deferred release: a resource the GPU may still use (a view replaced mid-run) is kept until
//! every frame submitted before its release has completed.

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::vk::Context;
use std::any::Any;
use std::collections::VecDeque;
use std::sync::Arc;

pub struct FrameRing {
    recorders: Vec<FrameRecorder>,
    /// The frame each slot holds (submitted, maybe completed).
    frame_in_slot: Vec<Option<u64>>,
    next_frame: u64,
    /// Every frame below this has completed (fences signal in submission order on one queue).
    completed_below: u64,
    deferred: VecDeque<(u64, Box<dyn Any>)>,
    /// Waits for the newest submitted frame: a drain of the pipeline. The steady state of a ring
    /// of N ≥ 2 has none (only `finish`, `wait_for` of the newest frame and N = 1 drain).
    drain_waits: u64,
}

impl FrameRing {
    pub fn new(ctx: &Arc<Context>, slots: usize, max_passes: u32) -> Result<FrameRing> {
        let slots = slots.max(1);
        Ok(FrameRing {
            recorders: (0..slots)
                .map(|_| FrameRecorder::new(ctx, max_passes))
                .collect::<Result<_>>()?,
            frame_in_slot: vec![None; slots],
            next_frame: 0,
            completed_below: 0,
            deferred: VecDeque::new(),
            drain_waits: 0,
        })
    }

    pub fn slots(&self) -> usize {
        self.recorders.len()
    }

    /// The slot the next frame will use.
    pub fn next_slot(&self) -> usize {
        (self.next_frame % self.slots() as u64) as usize
    }

    /// The id the next submitted frame gets.
    pub fn next_frame(&self) -> u64 {
        self.next_frame
    }

    pub fn drain_waits(&self) -> u64 {
        self.drain_waits
    }

    /// Frees the slot the next frame will use: waits for the frame in it (if still in flight)
    /// and returns that frame, whose results stay readable until the next `begin_next`.
    pub fn retire_next(&mut self) -> Result<Option<u64>> {
        let slot = self.next_slot();
        let Some(frame) = self.frame_in_slot[slot] else {
            return Ok(None);
        };
        self.wait_slot(slot, frame)?;
        Ok(Some(frame))
    }

    /// Waits for `frame` and every earlier frame still in flight, oldest first (a drain when
    /// `frame` is the newest).
    pub fn wait_for(&mut self, frame: u64) -> Result<()> {
        let first = frame.saturating_sub(self.slots() as u64 - 1);
        for f in first..=frame {
            if let Some(slot) = self.slot_of(f) {
                self.wait_slot(slot, f)?;
            }
        }
        Ok(())
    }

    /// Waits for every frame in flight, oldest first.
    pub fn finish(&mut self) -> Result<()> {
        if self.next_frame > 0 {
            self.wait_for(self.next_frame - 1)?;
        }
        // Nothing is in flight now: whatever was deferred can go.
        self.release_up_to(self.next_frame);
        Ok(())
    }

    /// The slot holding `frame`, if it was submitted and its slot not reused since.
    pub fn slot_of(&self, frame: u64) -> Option<usize> {
        let slot = (frame % self.slots() as u64) as usize;
        (self.frame_in_slot[slot] == Some(frame)).then_some(slot)
    }

    /// Whether `frame` has completed and its slot still holds its results.
    pub fn is_readable(&self, frame: u64) -> bool {
        self.slot_of(frame)
            .is_some_and(|slot| !self.recorders[slot].in_flight())
    }

    pub fn recorder(&self, slot: usize) -> &FrameRecorder {
        &self.recorders[slot]
    }

    /// Starts recording the next frame in its slot (retiring the slot's previous frame first).
    pub fn begin_next(&mut self) -> Result<(usize, &mut FrameRecorder)> {
        self.retire_next()?;
        let slot = self.next_slot();
        self.frame_in_slot[slot] = None;
        self.recorders[slot].begin()?;
        Ok((slot, &mut self.recorders[slot]))
    }

    /// Marks the frame recorded by the last `begin_next` as submitted; returns its id.
    pub fn submitted(&mut self) -> u64 {
        let frame = self.next_frame;
        let slot = self.next_slot();
        self.frame_in_slot[slot] = Some(frame);
        self.next_frame += 1;
        frame
    }

    /// Keeps `resource` alive until every frame submitted so far has completed.
    pub fn defer_release(&mut self, resource: Box<dyn Any>) {
        if self.next_frame <= self.completed_below {
            drop(resource);
        } else {
            self.deferred.push_back((self.next_frame, resource));
        }
    }

    /// Resources waiting for their frames.
    pub fn deferred_count(&self) -> usize {
        self.deferred.len()
    }

    fn wait_slot(&mut self, slot: usize, frame: u64) -> Result<()> {
        if self.recorders[slot].in_flight() {
            if frame + 1 == self.next_frame {
                self.drain_waits += 1;
            }
            self.recorders[slot].wait()?;
        }
        self.release_up_to(frame + 1);
        Ok(())
    }

    fn release_up_to(&mut self, completed_below: u64) {
        self.completed_below = self.completed_below.max(completed_below);
        while self
            .deferred
            .front()
            .is_some_and(|(frame, _)| *frame <= self.completed_below)
        {
            self.deferred.pop_front();
        }
    }
}

impl Drop for FrameRing {
    fn drop(&mut self) {
        // Deferred resources may still be in use by frames in flight.
        let _ = self.finish();
    }
}
