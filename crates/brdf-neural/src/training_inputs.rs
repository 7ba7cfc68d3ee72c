//! The inputs a training run keeps on the device: the spatial rows of its training and
//! validation points and its training records with their weights and targets, so that each
//! step uploads only its record indices ([`TrainingInputs`]). On the CPU, or past the size
//! limits, each part is `None` and batches gather their inputs on the host; the values are the
//! same either way.

use crate::fitted::{Records, device_table};
use crate::{Error, ModelConfig, RecordTable, Result, SpatialTable};
use burn::tensor::{Device, Tensor, TensorData};

/// What a training run keeps on the device ([`TrainingInputs::new`]).
pub struct TrainingInputs {
    /// The spatial rows of every training point, where each batch selects its rows
    /// ([`device_table`]); `None`: batches gather them on the CPU.
    pub spatial: Option<SpatialTable>,
    /// The validation points' rows on the inference device, where validation selects its
    /// records' rows.
    pub val_spatial: Option<SpatialTable>,
    /// Every training record's direction inputs, weight and target, where each batch selects
    /// its rows ([`device_records`]); `None`: batches gather them on the CPU.
    pub records: Option<DeviceRecords>,
}

impl TrainingInputs {
    /// The inputs of the training records `train` (each with its weight `E cos theta_l` and
    /// its target) and of the validation records `val` on `device` (an autodiff device;
    /// validation's rows go on its inference device) when `on_device` (the trainer's default
    /// on a GPU), each within its size limit.
    pub fn new(
        config: &ModelConfig,
        (train, weight, target): (Records, &[[f32; 3]], &[[f32; 3]]),
        val: Records,
        on_device: bool,
        device: &Device,
    ) -> Result<Self> {
        let spatial = device_table(config, train.points, on_device, device)?;
        let val_on_device = on_device && !val.is_empty();
        let val_spatial = device_table(config, val.points, val_on_device, &device.clone().inner())?;
        let table = spatial.as_ref();
        let records = device_records(config, train, weight, target, table, on_device, device)?;
        Ok(TrainingInputs { spatial, val_spatial, records })
    }
}

/// Training records on the device: their direction inputs ([`RecordTable`]), weights
/// (`E cos theta_l`) and targets (the observations' sRGB values), `[records, 3]` each.
pub struct DeviceRecords {
    /// The direction inputs and points.
    pub table: RecordTable,
    /// Each record's weight.
    pub weight: Tensor<2>,
    /// Each record's target.
    pub target: Tensor<2>,
}

/// Largest record table [`device_records`] puts on a GPU, in bytes, weights and targets
/// included.
pub const DEVICE_RECORDS_MAX_BYTES: usize = 4 << 30;

/// Every record on `device`, with its weight and target (one RGB triple a record each), when
/// `on_device` (the trainer's default on a GPU) and the model's spatial rows are there too
/// (`spatial`, from [`device_table`]): each batch then uploads only its record indices. `None`
/// otherwise, or past [`DEVICE_RECORDS_MAX_BYTES`].
pub fn device_records(
    config: &ModelConfig,
    records: Records,
    weight: &[[f32; 3]],
    target: &[[f32; 3]],
    spatial: Option<&SpatialTable>,
    on_device: bool,
    device: &Device,
) -> Result<Option<DeviceRecords>> {
    let n = records.len();
    if weight.len() != n || target.len() != n {
        return Err(Error::BatchShape(format!(
            "{n} records with {} weights and {} targets",
            weight.len(),
            target.len()
        )));
    }
    let bytes = RecordTable::bytes(config, n) + n * 6 * 4;
    if !on_device
        || (config.spatial_dim > 0 && spatial.is_none())
        || bytes > DEVICE_RECORDS_MAX_BYTES
    {
        return Ok(None);
    }
    let table = RecordTable::new(config, records.l, records.v, records.points.point, device)?;
    let rows = |x: &[[f32; 3]]| {
        Tensor::<2>::from_data(TensorData::new(x.as_flattened().to_vec(), [n, 3]), device)
    };
    Ok(Some(DeviceRecords { table, weight: rows(weight), target: rows(target) }))
}
