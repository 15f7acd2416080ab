merge -o shard.shard0of2.exr shard.shard0of2.exr shard.shard1of2.exr
