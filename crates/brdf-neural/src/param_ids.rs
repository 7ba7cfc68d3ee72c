//! Deterministic parameter ids. burn gives every parameter a random 64-bit id when a module is
//! built; the ids are stored in weight and checkpoint files (Adam's state is keyed by them), so
//! two fits of the same configuration and seed wrote files that differed in those bytes alone.
//! [`deterministic_ids`] renumbers a freshly built model's parameters in visiting order (a
//! SplitMix64 stream from a fixed start), so the same configuration always writes the same
//! bytes: a resumed run's files equal an uninterrupted one's.

use burn::module::{Module, ModuleMapper, Param, ParamId};
use burn::tensor::{Bool, Int, Tensor};

/// Hands out the ids in order.
struct Renumber(stdx::rng::SplitMix64);

impl Renumber {
    fn next(&mut self) -> ParamId {
        ParamId::from(self.0.next_u64())
    }
}

impl ModuleMapper for Renumber {
    fn map_float<const D: usize>(&mut self, mut param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        param.id = self.next();
        param
    }

    fn map_int<const D: usize>(
        &mut self,
        mut param: Param<Tensor<D, Int>>,
    ) -> Param<Tensor<D, Int>> {
        param.id = self.next();
        param
    }

    fn map_bool<const D: usize>(
        &mut self,
        mut param: Param<Tensor<D, Bool>>,
    ) -> Param<Tensor<D, Bool>> {
        param.id = self.next();
        param
    }
}

/// `module` with its parameters' ids replaced by a fixed sequence in visiting order.
pub fn deterministic_ids<M: Module>(module: M) -> M {
    module.map(&mut Renumber(stdx::rng::SplitMix64::new(0x6e62_7264_665f_6964)))
}
